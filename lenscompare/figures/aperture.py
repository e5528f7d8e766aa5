"""Figure: where the geometric models stop — the best aperture, and the blades.

Left: the blur spot of a point at ``object_distance_m`` when the thin lens is
focused at ``focus_distance_m``, against the f-number. Geometric defocus (eq. 5,
c = (f / N) |l' − d'| / l') falls as 1/N; the Airy disk of diffraction
(2.44 λ N_w at 550 nm, N_w = N d' / f) grows as N. Their sum is smallest at
N* = sqrt(A / B) for c = A / N and Airy = B N, where both are A / N* — the
aperture a photographer stops down to and no further. The pixel pitch is
drawn for scale.

Right: a defocused point (5 m, focus 2 m, 50 mm at f/2) rendered by the
native thin lens through 5, 6, 7 and 9 blades (the aperture's shape, same area as the circle), and below each the
aperture's diffraction PSF (log scale): a star of 2N spikes for odd N, N for
even N (opposite edges of an even polygon are parallel and share their
spikes).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from ..optics import circle_of_confusion_mm, focus_film_distance_mm
from ..optics.diffraction import REFERENCE_WAVELENGTH_NM, airy_diameter_mm, pupil_psf
from ..render import render
from ..scene import Camera, EmissiveMaterial, RenderSettings, Scene, Sphere
from . import _style

__all__ = ["ApertureGeometry", "aperture_geometry", "aperture_figure", "BLADES"]

BLADES = (5, 6, 7, 9)
BOKEH_PX = 80        # the rendered bokeh's image, square
BOKEH_SPP = 512
PSF_HALF_WIDTH = 8.0  # the PSF panels show ±8 λ N_w


@dataclass(frozen=True)
class ApertureGeometry:
    """What the figure draws.

    Attributes
    ----------
    f_numbers : ndarray
        The f-numbers of the curves.
    defocus_um, diffraction_um : ndarray
        Geometric blur-spot diameter (eq. 5) and Airy-disk diameter at each.
    best_f_number, best_sum_um : float
        Where defocus + diffraction is smallest (closed form), and that sum.
    pixel_um : float
        The film's pixel pitch, for scale.
    focal_length_mm, focus_distance_m, object_distance_m : float
    bokeh : dict of int to ndarray
        Blades -> the rendered defocused point (linear, green channel).
    psf : dict of int to ndarray
        Blades -> the diffraction PSF, ±PSF_HALF_WIDTH λ N_w, rows up.
    """

    f_numbers: np.ndarray
    defocus_um: np.ndarray
    diffraction_um: np.ndarray
    best_f_number: float
    best_sum_um: float
    pixel_um: float
    focal_length_mm: float
    focus_distance_m: float
    object_distance_m: float
    bokeh: dict = field(default_factory=dict)
    psf: dict = field(default_factory=dict)


@functools.lru_cache(maxsize=len(BLADES))  # deterministic: the same render each time a process draws the figure
def _bokeh(blades: int, *, focal_length_mm: float = 50.0, focus_distance_m: float = 2.0,
           object_distance_m: float = 5.0) -> np.ndarray:
    """A point at ``object_distance_m`` on the axis (behind the focus: the
    aperture upright), rendered at f/2 so that its blur fills most of a small
    film."""
    f_number = 2.0
    c_mm = circle_of_confusion_mm(object_distance_m * 1000.0, focus_distance_mm=focus_distance_m * 1000.0,
                                  focal_length_mm=focal_length_mm, aperture_diameter_mm=focal_length_mm / f_number)
    film_mm = 1.5 * c_mm * 1.15  # room for the polygon's corners
    d_prime = focus_film_distance_mm(focus_distance_m * 1000.0, focal_length_mm)
    # The source images to a quarter of the blur: light enough per sample, edges still sharp.
    radius_m = c_mm / 8.0 * object_distance_m / d_prime
    camera = Camera(model="thin", position=(0.0, 0.0, 0.0), look_at=(0.0, 0.0, 1.0), up=(0.0, 1.0, 0.0),
                    focus_distance_m=focus_distance_m, resolution=(BOKEH_PX, BOKEH_PX), film_mm=(film_mm, film_mm),
                    focal_length_mm=focal_length_mm, f_number=f_number, aperture_blades=blades)
    scene = Scene(camera=camera, render=RenderSettings(spp=BOKEH_SPP, sampler="sobol"), background=(0.0, 0.0, 0.0),
                  materials={"glow": EmissiveMaterial("glow", (1.0, 1.0, 1.0))},
                  objects=(Sphere((0.0, 0.0, object_distance_m), radius_m, "glow"),), lights=(), name="bokeh")
    image = render(scene, progress=False).pixels[..., 1]
    image.setflags(write=False)  # shared by the cache
    return image


def _psf(blades: int) -> np.ndarray:
    psf = pupil_psf(blades, 0.0, samples_across=64, spacing=0.125)
    n = psf.intensity.shape[0]
    half = int(PSF_HALF_WIDTH / psf.spacing)
    return psf.intensity[n // 2 - half:n // 2 + half + 1, n // 2 - half:n // 2 + half + 1]


def aperture_geometry(*, focal_length_mm: float = 50.0, focus_distance_m: float = 2.0, object_distance_m: float = 5.0,
                      pixel_pitch_mm: float = 0.004, f_numbers=None, images: bool = True) -> ApertureGeometry:
    """The figure's numbers; ``images`` False skips the renders and PSFs."""
    f_numbers = np.geomspace(1.4, 64.0, 200) if f_numbers is None else np.asarray(f_numbers, dtype=float)
    d_prime = focus_film_distance_mm(focus_distance_m * 1000.0, focal_length_mm)
    defocus = np.array([circle_of_confusion_mm(object_distance_m * 1000.0, focus_distance_mm=focus_distance_m * 1000.0,
                                               focal_length_mm=focal_length_mm, aperture_diameter_mm=focal_length_mm / n)
                        for n in f_numbers])
    diffraction = np.array([airy_diameter_mm(REFERENCE_WAVELENGTH_NM, n * d_prime / focal_length_mm)
                            for n in f_numbers])
    a = float(defocus[0] * f_numbers[0])                  # defocus = a / N
    b = float(diffraction[0] / f_numbers[0])              # Airy = b N
    best = max(math.sqrt(a / b), float(f_numbers[0]))     # an object in focus: wide open is best
    bokeh, psf = {}, {}
    if images:
        for blades in BLADES:
            bokeh[blades] = _bokeh(blades)
            psf[blades] = _psf(blades)
    return ApertureGeometry(f_numbers=f_numbers, defocus_um=1000.0 * defocus, diffraction_um=1000.0 * diffraction,
                            best_f_number=best, best_sum_um=1000.0 * (a / best + b * best),
                            pixel_um=1000.0 * pixel_pitch_mm, focal_length_mm=focal_length_mm,
                            focus_distance_m=focus_distance_m, object_distance_m=object_distance_m,
                            bokeh=bokeh, psf=psf)


def aperture_figure(geometry: ApertureGeometry):
    """The figure (a :class:`matplotlib.figure.Figure`)."""
    g = geometry
    with _style.figure_style():
        fig = _style.new_figure(11.0, 4.6)
        grid = fig.add_gridspec(2, 1 + len(BLADES), width_ratios=[3.2] + [1.0] * len(BLADES))
        ax = fig.add_subplot(grid[:, 0])
        ax.plot(g.f_numbers, g.defocus_um, color=_style.BUNDLES[0], lw=1.6, gid="defocus-curve",
                label=f"defocus (eq. 5): point at {g.object_distance_m:g} m, focus {g.focus_distance_m:g} m")
        ax.plot(g.f_numbers, g.diffraction_um, color=_style.BUNDLES[1], lw=1.6, gid="diffraction-curve",
                label="diffraction: Airy disk 2.44 \u03bb $N_w$ at 550 nm")
        ax.plot(g.f_numbers, g.defocus_um + g.diffraction_um, color="black", lw=1.2, ls=(0, (4, 2)),
                gid="sum-curve", label="their sum")
        ax.axhline(g.pixel_um, color=_style.MUTED, lw=0.8, ls=(0, (1, 2)), gid="pixel")
        ax.annotate(f"one pixel ({g.pixel_um:g} \u00b5m)", (g.f_numbers[0], g.pixel_um), xytext=(2, 2),
                    textcoords="offset points", fontsize=7.5, color=_style.MUTED)
        ax.plot([g.best_f_number], [g.best_sum_um], "o", color="black", ms=5, zorder=5, gid="best-aperture")
        ax.annotate(f"best: f/{g.best_f_number:.3g}\n{g.best_sum_um:.3g} \u00b5m", (g.best_f_number, g.best_sum_um),
                    xytext=(0, 10), textcoords="offset points", ha="center", va="bottom", fontsize=8,
                    bbox=_style.LABEL_BOX)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ticks = [n for n in (1.4, 2, 2.8, 4, 5.6, 8, 11, 16, 22, 32, 45, 64)
                 if g.f_numbers.min() <= n <= g.f_numbers.max()]
        ax.set_xticks(ticks, [f"f/{n:g}" for n in ticks])
        ax.minorticks_off()
        ax.set_xlabel("f-number N")
        ax.set_ylabel("blur-spot diameter on the film (\u00b5m)")
        ax.set_title(f"Stopping down: defocus falls, diffraction grows ({g.focal_length_mm:g} mm lens)")
        ax.legend(loc="upper center", fontsize=7.5)
        for i, blades in enumerate(b for b in BLADES if b in g.bokeh):
            top = fig.add_subplot(grid[0, 1 + i])
            top.imshow(g.bokeh[blades], cmap="gray", interpolation="nearest", gid=f"bokeh-{blades}")
            top.set_title(f"{blades} blades", fontsize=8.5)
            bottom = fig.add_subplot(grid[1, 1 + i])
            psf = g.psf[blades]
            bottom.imshow(np.log10(np.maximum(psf / psf.max(), 1e-6)), cmap="magma", vmin=-6, vmax=0,
                          origin="lower", interpolation="nearest", gid=f"psf-{blades}")
            spikes = 2 * blades if blades % 2 else blades
            bottom.set_title(f"PSF: {spikes} spikes", fontsize=8)
            for a in (top, bottom):
                a.set_xticks([])
                a.set_yticks([])
        fig.text(0.99, 0.005, "top: defocused point, native thin lens; bottom: |FFT of the pupil|\u00b2, "
                 f"\u00b1{PSF_HALF_WIDTH:g} \u03bb N, log scale (6 decades)", ha="right", va="bottom",
                 fontsize=7, color=_style.MUTED)
    return fig
