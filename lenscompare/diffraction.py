"""Diffraction applied to a rendered image: the aperture's Fraunhofer PSF
(:mod:`lenscompare.optics.diffraction`) at the camera's working f-number,
integrated over the film's pixels, convolved with the image by FFT.

The renders trace geometric optics; diffraction blurs their image by one
PSF (the on-axis one) over the whole film: the convolution. Which PSF:

- thin and thick lens: the aperture (circle or N-gon) at N_w = d' / D;
- lens system: the exit pupil's shape on the axis, the stop's own (circle or
  N-gon; an image of the stop has its shape), at N_w = film distance from the
  paraxial exit pupil over its diameter. Off the axis the real exit pupil is
  cut by vignetting (a cat's eye), which is not modelled;
- pinhole: no aperture of its own; it stands for the lens in perfect focus,
  so the PSF is the thin lens's at the scene's f-number.

Non-spectral renders average the PSF over :data:`~lenscompare.optics.diffraction.BAND_NM`
(400-700 nm, 10 nm steps), each channel weighted by its colour-matching
function (:func:`~lenscompare.optics.diffraction.channel_weights`): red
blurs more than blue. The image is padded by reflection at its borders
(light from just outside the frame is taken to be like that just inside).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from scipy import fft

from .cameras import CameraModel, camera_for
from .errors import InputError
from .lenses import paraxial_data
from .optics.diffraction import (BAND_NM, REFERENCE_WAVELENGTH_NM, airy_diameter_mm, channel_weights, pixel_kernel,
                                 pupil_psf)
from .scene import Scene

__all__ = ["DiffractionAperture", "diffraction_aperture", "diffraction_kernel", "diffract", "convolve_image"]

# The PSF's field spans PUPIL_SAMPLES λ·N_w: the kernel reaches ±32 λ·N_w (at
# the shortest wavelength), which holds all but 0.6 % of an Airy pattern's
# energy (under 1 % over the band); that rest, the faint far tails, is spread
# evenly (see diffract). A PSF much smaller than a pixel gets a field of at
# least MIN_RADIUS_PX pixels.
# Its grid is at most MAX_FFT samples wide, which a PSF many pixels wide buys
# with a narrower field.
PUPIL_SAMPLES = 64
MIN_PUPIL_SAMPLES = 32
MIN_RADIUS_PX = 3
MAX_RADIUS_PX = 512  # beyond, the veil takes the energy (an Airy disk hundreds of pixels wide)
MAX_FFT = 2048


@dataclass(frozen=True)
class DiffractionAperture:
    """What the diffraction PSF depends on."""

    working_f_number: float
    blades: int
    rotation_deg: float
    pixel_pitch_mm: float

    def airy_diameter_px(self, wavelength_nm: float = REFERENCE_WAVELENGTH_NM) -> float:
        return airy_diameter_mm(wavelength_nm, self.working_f_number) / self.pixel_pitch_mm


def diffraction_aperture(scene: Scene, camera: CameraModel) -> DiffractionAperture:
    """The aperture that diffracts for ``camera`` (see the module notes);
    an :class:`InputError` when there is none (a pinhole scene without an
    f-number)."""
    if camera.working_f_number is None:
        f_number = scene.camera.f_number
        if f_number is None and scene.camera.lens is None:
            raise InputError(scene.source, "the pinhole has no aperture to diffract; give camera.f_number (the "
                             "pinhole then stands for the thin lens in perfect focus)", key="render.diffraction")
        if f_number is None:
            f_number = paraxial_data(scene.camera.lens).f_number  # the lens wide open
        camera = camera_for(scene.with_camera(f_number=f_number), "thin")
    return DiffractionAperture(working_f_number=camera.working_f_number, blades=camera.aperture_blades,
                               rotation_deg=camera.aperture_rotation_deg, pixel_pitch_mm=camera.pixel_pitch_mm)


def diffraction_kernel(aperture: DiffractionAperture, *, wavelengths_nm=BAND_NM, weights=None,
                       max_radius_px: int | None = None) -> np.ndarray:
    """The pixel kernel, (2R + 1, 2R + 1, C): the fraction of a point's energy
    each pixel receives (a channel sums to 1 less what falls beyond R).

    ``weights`` (C, L) default to the colour-matching functions of
    ``wavelengths_nm`` (C = 3); one wavelength with weights ``[[1.0]]`` gives
    the monochromatic PSF. R reaches the PSF's field at the shortest
    wavelength, at most ``max_radius_px``.
    """
    wavelengths_nm = [float(w) for w in wavelengths_nm]
    weights = channel_weights(wavelengths_nm) if weights is None else np.atleast_2d(weights)
    n_w, pitch = aperture.working_f_number, aperture.pixel_pitch_mm
    # PSF samples 1/12 of λ N_w apart, at most a quarter pixel at the longest
    # wavelength: each pixel integrates the PSF as constant over a sample's
    # cell, which errs by ~(spacing / pixel)² on a peak narrower than a pixel
    # (0.4 % on the centre pixel here), and by ~spacing on a wide one.
    spacing = min(1.0 / 12.0, pitch / (4.0 * max(wavelengths_nm) * 1e-6 * n_w))
    # ... but never so fine that the smallest pupil overflows MAX_FFT (a PSF
    # hundreds of pixels wide: its cells then span several pixels).
    spacing = max(spacing, MIN_PUPIL_SAMPLES / MAX_FFT)
    # Enough field for MIN_RADIUS_PX pixels round the point however small the PSF, within MAX_FFT.
    reach = 2.0 * (MIN_RADIUS_PX + 1) * pitch / (min(wavelengths_nm) * 1e-6 * n_w)
    samples = int(max(MIN_PUPIL_SAMPLES, min(max(PUPIL_SAMPLES, reach), MAX_FFT * spacing)))
    psf = pupil_psf(aperture.blades, float(aperture.rotation_deg), samples_across=samples, spacing=spacing)
    field_px = psf.half_field * min(wavelengths_nm) * 1e-6 * n_w / pitch
    radius = min(max(1, int(math.floor(field_px - 0.5))), MAX_RADIUS_PX)
    if max_radius_px is not None:
        radius = max(1, min(radius, int(max_radius_px)))
    return pixel_kernel(psf, pixel_pitch_mm=pitch, working_f_number=n_w, wavelengths_nm=wavelengths_nm,
                        weights=weights, radius_px=radius)


def convolve_image(pixels: np.ndarray, kernel: np.ndarray) -> np.ndarray:
    """``pixels`` (H, W, C) convolved with ``kernel`` (2R + 1, 2R + 1, C), the
    borders padded by reflection; same shape and dtype out. One real FFT per
    channel and size, float32."""
    radius = kernel.shape[0] // 2
    height, width = pixels.shape[:2]
    pad = radius  # mirrored as often as the kernel's reach needs, also beyond a small image's size
    padded = np.pad(pixels.astype(np.float32, copy=False), ((pad, pad), (pad, pad), (0, 0)), mode="symmetric")
    # No wrap-around reaches the pixels kept: H + pad + R samples suffice.
    shape = [fft.next_fast_len(height + pad + radius, real=True), fft.next_fast_len(width + pad + radius, real=True)]
    spectrum = fft.rfft2(padded, s=shape, axes=(0, 1), workers=-1)
    # The kernel's rows first, then its columns: only 2R + 1 of its rows are not zero.
    rows = fft.rfft(kernel.astype(np.float32), n=shape[1], axis=1, workers=-1)
    spectrum *= fft.fft(rows, n=shape[0], axis=0, workers=-1)
    out = fft.irfft2(spectrum, s=shape, axes=(0, 1), workers=-1)
    # The kernel's centre sits at (radius, radius): output pixel n is at n + radius of the padded image.
    return np.ascontiguousarray(out[pad + radius:pad + radius + height, pad + radius:pad + radius + width],
                                dtype=pixels.dtype)


def diffract(pixels: np.ndarray, variance: np.ndarray | None, aperture: DiffractionAperture, *,
             wavelengths_nm=BAND_NM, weights=None) -> tuple[np.ndarray, np.ndarray | None, dict]:
    """An image with the aperture's diffraction PSF applied.

    Parameters
    ----------
    pixels : ndarray, (H, W, 3)
        A render's linear pixels.
    variance : ndarray, (H, W), or None
        The variance of each pixel's mean; carried through as Σ K² var
        (pixels independent).
    aperture : DiffractionAperture
        :func:`diffraction_aperture` of the render's scene and camera.
    wavelengths_nm, weights : optional
        The band and each channel's weights (default: 400-700 nm with the
        colour-matching functions).

    Returns
    -------
    pixels, variance, info
        ``info`` says what was applied and what it cost (``seconds``), for
        the image's metadata.
    """
    start = time.perf_counter()
    height, width = pixels.shape[:2]
    kernel = diffraction_kernel(aperture, wavelengths_nm=wavelengths_nm, weights=weights,
                                max_radius_px=max(height, width))
    out = convolve_image(pixels, kernel)
    # The PSF's energy beyond the kernel (its far tails, smooth and faint)
    # spread evenly: each channel's mean times that fraction. A uniform scene
    # stays uniform; a point keeps its true encircled energy.
    mean = pixels.reshape(-1, pixels.shape[2]).sum(axis=0, dtype=np.float64) / (height * width)
    out += ((1.0 - kernel.sum(axis=(0, 1))) * mean).astype(out.dtype)
    if variance is not None:
        squared = np.mean(kernel, axis=2, keepdims=True) ** 2
        variance = convolve_image(variance[:, :, None], squared)[:, :, 0]
    wavelengths = [float(w) for w in wavelengths_nm]
    info = {"working_f_number": aperture.working_f_number, "aperture_blades": aperture.blades,
            "aperture_rotation_deg": aperture.rotation_deg,
            "airy_diameter_px_550nm": aperture.airy_diameter_px(),
            "wavelengths_nm": [min(wavelengths), max(wavelengths), len(wavelengths)],
            "kernel_radius_px": kernel.shape[0] // 2,
            "energy_beyond_kernel": float(1.0 - kernel.sum(axis=(0, 1)).mean()), "seconds": time.perf_counter() - start}
    return out, variance, info
