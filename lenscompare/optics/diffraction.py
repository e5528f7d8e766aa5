"""Fraunhofer diffraction by the lens aperture: the point-spread function as
the squared magnitude of the pupil's Fourier transform, its closed form for a
circle (Airy), and the pixel kernel a rendered image is convolved with.

Lengths on the film are measured in units of λ·N_w (the wavelength times the
working f-number, film distance over exit-pupil diameter): in those units the
monochromatic PSF of a given pupil *shape* is one function for every
wavelength and f-number, computed once (:func:`pupil_psf`). A pupil of
``D`` samples across (the circle's diameter) in an FFT of ``P`` samples puts
the PSF's samples ``D / P`` apart, and its field spans ``D`` (±D/2).

The pixel kernel (:func:`pixel_kernel`) integrates the PSF over each pixel's
footprint on the film (the film's pixel pitch; a PSF narrower than a pixel
stays in that pixel, none of its energy falls between samples), one
wavelength at a time, weighted per colour channel.

References
----------
Born, M. & Wolf, E. *Principles of Optics*, 7th ed., §8.5 (Airy pattern:
first zero at v = 3.8317, 83.8 % of the energy inside it).
Goodman, J. W. *Introduction to Fourier Optics*, 3rd ed., §4.4 and §6.2
(Fraunhofer diffraction by an aperture; the incoherent PSF).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from scipy import fft, special

from .aperture import inside_aperture, polygon_circumradius

__all__ = [
    "AIRY_FIRST_ZERO", "REFERENCE_WAVELENGTH_NM", "BAND_NM", "airy_first_zero_radius_mm", "airy_diameter_mm",
    "airy_intensity", "airy_encircled_energy", "pupil_coverage", "PupilPSF", "pupil_psf", "pixel_kernel",
    "channel_weights", "colour_matching_functions",
]

AIRY_FIRST_ZERO = 3.8317059702075125 / math.pi
"""First dark ring of the Airy pattern in units of λ·N: j₁,₁ / π = 1.21967."""

REFERENCE_WAVELENGTH_NM = 550.0
"""The wavelength the planner sizes diffraction at (DESIGN.md)."""

BAND_NM = tuple(float(w) for w in range(400, 701, 10))
"""Wavelengths a non-spectral render's diffraction is averaged over: 400-700 nm in
10 nm steps, each colour channel weighted by :func:`channel_weights`."""


def airy_first_zero_radius_mm(wavelength_nm: float, working_f_number: float) -> float:
    """Radius of the Airy pattern's first dark ring, 1.22 λ N, mm.

    Examples
    --------
    >>> round(airy_first_zero_radius_mm(550.0, 16.0) * 1000.0, 3)  # µm
    10.733
    """
    return AIRY_FIRST_ZERO * wavelength_nm * 1e-6 * working_f_number


def airy_diameter_mm(wavelength_nm: float, working_f_number: float) -> float:
    """Diameter of the Airy disk (to the first dark ring), 2.44 λ N, mm."""
    return 2.0 * airy_first_zero_radius_mm(wavelength_nm, working_f_number)


def _airy_v(radius_mm, wavelength_nm: float, working_f_number: float):
    return math.pi * np.asarray(radius_mm, dtype=float) / (wavelength_nm * 1e-6 * working_f_number)


def airy_intensity(radius_mm, *, wavelength_nm: float, working_f_number: float) -> np.ndarray:
    """The Airy pattern (2 J₁(v) / v)², 1 at the centre; v = π r / (λ N)."""
    v = _airy_v(radius_mm, wavelength_nm, working_f_number)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(v > 0, (2.0 * special.j1(v) / np.where(v > 0, v, 1.0)) ** 2, 1.0)


def airy_encircled_energy(radius_mm, *, wavelength_nm: float, working_f_number: float) -> np.ndarray:
    """Fraction of the Airy pattern's energy within ``radius_mm``: 1 − J₀²(v) − J₁²(v).

    Examples
    --------
    >>> r = airy_first_zero_radius_mm(550.0, 8.0)
    >>> round(float(airy_encircled_energy(r, wavelength_nm=550.0, working_f_number=8.0)), 4)
    0.8378
    """
    v = _airy_v(radius_mm, wavelength_nm, working_f_number)
    return 1.0 - special.j0(v) ** 2 - special.j1(v) ** 2


def pupil_coverage(blades: int, rotation_deg: float, *, samples_across: float, size: int,
                   supersample: int = 4) -> np.ndarray:
    """The pupil on a ``size`` × ``size`` grid: each cell's covered fraction.

    The circle (``blades`` 0) has a diameter of ``samples_across`` cells; the
    N-gon has its area. Centred on cell ``size // 2``; rows run along +y (up),
    columns along +x. Coverage is estimated on ``supersample``² points per cell
    so that the edge is anti-aliased (a staircase edge would add its own
    diffraction spikes along the grid axes).
    """
    radius = 0.5 * samples_across
    reach = radius * (polygon_circumradius(blades) if blades else 1.0)
    half = int(math.ceil(reach)) + 1
    if 2 * half + 1 > size:
        raise ValueError(f"a pupil {samples_across:g} samples across does not fit a {size}-sample grid")
    offsets = (np.arange(supersample) + 0.5) / supersample - 0.5
    cells = np.arange(-half, half + 1, dtype=float)
    sub = (cells[:, None] + offsets[None, :]).ravel()
    y, x = np.meshgrid(sub, sub, indexing="ij")
    inside = inside_aperture(x, y, blades=blades, rotation_deg=rotation_deg, radius=radius)
    n = 2 * half + 1
    block = inside.reshape(n, supersample, n, supersample).mean(axis=(1, 3))
    grid = np.zeros((size, size))
    c = size // 2
    grid[c - half:c + half + 1, c - half:c + half + 1] = block
    return grid


@dataclass(frozen=True)
class PupilPSF:
    """A monochromatic PSF on the film, lengths in units of λ·N_w.

    Attributes
    ----------
    intensity : ndarray, (P, P)
        The fraction of the energy in each sample (1 in all, less the tails
        beyond the field); centre at ``[P // 2, P // 2]``; rows along +y (up), columns
        along +x, as the pupil (camera x right, y up).
    spacing : float
        Distance between samples, in units of λ·N_w.
    """

    intensity: np.ndarray
    spacing: float

    @functools.cached_property
    def summed_area(self) -> np.ndarray:
        """(P + 1, P + 1): the energy in samples [0, i) × [0, j)."""
        n = self.intensity.shape[0]
        table = np.zeros((n + 1, n + 1))
        np.cumsum(self.intensity, axis=0, out=table[1:, 1:])
        np.cumsum(table[1:, 1:], axis=1, out=table[1:, 1:])
        return table

    @property
    def half_field(self) -> float:
        """Half the width of the field, in units of λ·N_w."""
        return 0.5 * self.spacing * self.intensity.shape[0]


@functools.lru_cache(maxsize=16)
def pupil_psf(blades: int = 0, rotation_deg: float = 0.0, *, samples_across: int = 128,
              spacing: float = 0.25) -> PupilPSF:
    """|FFT of the pupil|², normalised: the Fraunhofer PSF of the aperture.

    Parameters
    ----------
    blades, rotation_deg : int, float
        The aperture's shape (:mod:`lenscompare.optics.aperture`).
    samples_across : int
        The pupil circle's diameter in samples. The PSF's field is this many
        λ·N_w wide; energy beyond it (the Airy pattern's far tails, 0.3 % at
        128) folds back into the field.
    spacing : float
        The PSF's sample spacing in units of λ·N_w (at most 1/2 for the
        intensity's band limit; finer to resolve small pixels).

    Returns
    -------
    PupilPSF
    """
    size = fft.next_fast_len(int(math.ceil(samples_across / spacing)))
    pupil = pupil_coverage(blades, rotation_deg, samples_across=samples_across, size=size)
    field = fft.fft2(fft.ifftshift(pupil), workers=-1)
    # Coverage is the sharp pupil blurred by one cell (a box): undo its sinc
    # in the field, or the soft edge would apodise the pupil (about 1 % of
    # the energy moved from the rings into the core at 60 samples across).
    box = np.sinc(fft.fftfreq(size))
    intensity = fft.fftshift(np.abs(field / np.outer(box, box)) ** 2)
    # The energy through the pupil is its area (Parseval on the sharp pupil):
    # the grid then holds 1 less what lies beyond its field.
    intensity /= size * size * pupil.sum()
    return PupilPSF(intensity=intensity, spacing=samples_across / size)


def _box_integrals(psf: PupilPSF, edges: np.ndarray) -> np.ndarray:
    """∫ of the PSF over each cell [edges[i], edges[i+1]] × [edges[j], edges[j+1]]
    (units of λ·N_w; rows along +y), from its summed-area table: the PSF is
    read as constant over each of its own cells, so the integral is exact for
    that reading at any pixel size."""
    n = psf.intensity.shape[0]
    sat = psf.summed_area
    # Fractional index of each edge in the table: sample k covers (k - n//2 ± 1/2) spacing.
    t = np.clip(edges / psf.spacing + n // 2 + 0.5, 0.0, float(n))
    i0 = np.minimum(t.astype(int), n - 1)
    f = t - i0
    rows = sat[i0] * (1.0 - f)[:, None] + sat[i0 + 1] * f[:, None]          # along y
    table = rows[:, i0] * (1.0 - f)[None, :] + rows[:, i0 + 1] * f[None, :]  # along x
    return np.diff(np.diff(table, axis=0), axis=1)


def pixel_kernel(psf: PupilPSF, *, pixel_pitch_mm: float, working_f_number: float, wavelengths_nm,
                 weights, radius_px: int) -> np.ndarray:
    """The PSF integrated over each pixel's footprint, summed over wavelengths.

    Parameters
    ----------
    psf : PupilPSF
        The aperture's monochromatic PSF (:func:`pupil_psf`).
    pixel_pitch_mm, working_f_number : float
        The film's pixel pitch; film distance over exit-pupil diameter.
    wavelengths_nm : sequence of float
        Wavelengths, nm.
    weights : ndarray, (C, L)
        Each channel's weight per wavelength (each row is normalised to sum 1).
    radius_px : int
        The kernel's half-size; it should lie within the PSF's field at the
        shortest wavelength (``psf.half_field`` · λ · N_w).

    Returns
    -------
    ndarray, (2 radius + 1, 2 radius + 1, C)
        The fraction of a point's energy that reaches each pixel: a channel
        sums to less than 1 by what falls beyond the kernel (the Airy
        pattern's tails hold 1 % beyond 25 λ N). Row 0 is the top (image
        rows run down); the centre is the pixel the point lies in.
    """
    weights = np.atleast_2d(np.asarray(weights, dtype=float))
    weights = weights / weights.sum(axis=1, keepdims=True)
    offsets = np.arange(-radius_px, radius_px + 2) - 0.5  # pixel edges, px
    kernel = np.zeros((2 * radius_px + 1, 2 * radius_px + 1, weights.shape[0]))
    for wavelength, w in zip(wavelengths_nm, weights.T):
        if not np.any(w):
            continue
        scale = pixel_pitch_mm / (wavelength * 1e-6 * working_f_number)  # one pixel in units of λ·N_w
        energy = _box_integrals(psf, offsets * scale)
        kernel += energy[:, :, None] * w[None, None, :]
    return kernel[::-1]  # rows along +y -> image rows, top first


# CIE 1931 XYZ -> linear sRGB (IEC 61966-2-1), the primaries the EXR's RGB are in.
_SRGB_FROM_XYZ = np.array([[3.2406, -1.5372, -0.4986], [-0.9689, 1.8758, 0.0415], [0.0557, -0.2040, 1.0570]])

# CIE 1931 2° colour-matching functions x̄, ȳ, z̄ at 400-700 nm, 10 nm steps
# (CIE 015:2018 table; the same as colour-science's, tested): written out so
# that a render need not import colour-science (seconds) to diffract.
_CMF_NM = np.arange(400.0, 701.0, 10.0)
_CMF_XYZ = np.array([
    [0.014310, 0.000396, 0.067850], [0.043510, 0.001210, 0.207400], [0.134380, 0.004000, 0.645600],
    [0.283900, 0.011600, 1.385600], [0.348280, 0.023000, 1.747060], [0.336200, 0.038000, 1.772110],
    [0.290800, 0.060000, 1.669200], [0.195360, 0.090980, 1.287640], [0.095640, 0.139020, 0.812950],
    [0.032010, 0.208020, 0.465180], [0.004900, 0.323000, 0.272000], [0.009300, 0.503000, 0.158200],
    [0.063270, 0.710000, 0.078250], [0.165500, 0.862000, 0.042160], [0.290400, 0.954000, 0.020300],
    [0.433450, 0.994950, 0.008750], [0.594500, 0.995000, 0.003900], [0.762100, 0.952000, 0.002100],
    [0.916300, 0.870000, 0.001650], [1.026300, 0.757000, 0.001100], [1.062200, 0.631000, 0.000800],
    [1.002600, 0.503000, 0.000340], [0.854450, 0.381000, 0.000190], [0.642400, 0.265000, 0.000050],
    [0.447900, 0.175000, 0.000020], [0.283500, 0.107000, 0.000000], [0.164900, 0.061000, 0.000000],
    [0.087400, 0.032000, 0.000000], [0.046770, 0.017000, 0.000000], [0.022700, 0.008210, 0.000000],
    [0.011359, 0.004102, 0.000000],
])


def colour_matching_functions(wavelengths_nm) -> np.ndarray:
    """(L, 3): CIE 1931 2° x̄, ȳ, z̄, linear between the 10 nm table's rows
    (400-700 nm), 0 outside it."""
    w = np.asarray(wavelengths_nm, dtype=float)
    return np.stack([np.interp(w, _CMF_NM, _CMF_XYZ[:, i], left=0.0, right=0.0) for i in range(3)], axis=-1)


def channel_weights(wavelengths_nm) -> np.ndarray:
    """(3, L): how much each wavelength of an equal-energy white source adds
    to linear sRGB R, G, B: the CIE 1931 2° colour-matching functions through
    the sRGB matrix, negative lobes clipped to 0, each row normalised to sum 1."""
    rgb = np.clip(colour_matching_functions(wavelengths_nm) @ _SRGB_FROM_XYZ.T, 0.0, None).T
    return rgb / rgb.sum(axis=1, keepdims=True)
