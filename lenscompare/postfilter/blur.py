"""Each pixel's blur disk (eq. 5) and its spread over the image.

Scatter, not gather. Every pixel of the pinhole image spreads its colour over
its own circle of confusion (the aperture's N-gon when it has blades), as a
lens spreads a point: a blurred foreground object then reaches over a sharp
background, which a gather (each pixel averaging its neighbours within its
own blur) cannot do, and a sharp foreground keeps the blurred background
from leaking onto it. Gather is cheaper on a GPU, but it leaks both ways.

Occlusion: the pixels are sorted into depth layers (by signed blur diameter,
1 px wide up to 10 px, then 10 % wide), each layer is spread, and the layers
are composited back to front ("over", after Kraus and Strengert 2007), so a
nearer layer's spread covers what lies behind it by its own coverage. Before
each layer goes over, what lies behind is normalised by the coverage it
received: the holes that nearer objects left in a blurred background, and the
frame's border, are filled from their surroundings, and a point's blur keeps
its flux. What a single image cannot hold, the surfaces hidden behind a
foreground object, is missing: the error at occlusion edges (:mod:`.edges`).

The spread is exact in each pixel's own diameter (no size classes): its
kernel is the disk (or N-gon; upright behind the plane of focus, turned by
180 degrees in front) box-filtered across each row and integrated at
``SUB_ROWS`` heights per row, normalised to the pixel's colour. Drawn on the
pixel grid a kernel's variance is not its own (under half a pixel it adds
nothing; far above, it adds the output pixel's box, 1/12 px² per axis, which
the pinhole's own pixel already holds), so each kernel is drawn at the
radius whose grid variance is the aperture's (a table, inverted): every blur
adds exactly its eq.-5 second moment, a 1 px blur spreads a little into the
neighbours as the thin lens's does, and a blur under 0.01 px keeps the pixel
bit for bit (a scene in the plane of focus comes out as its pinhole image).

References
----------
.. [1] M. Potmesil, I. Chakravarty, "A lens and aperture camera model for
   synthetic image generation", SIGGRAPH 1981, 297-305, doi:10.1145/965161.806818.
.. [2] M. Kraus, M. Strengert, "Depth-of-field rendering by pyramidal image
   processing", Computer Graphics Forum 26(3), 2007, doi:10.1111/j.1467-8659.2007.01095.x.
"""

from __future__ import annotations

import os
import time

import numpy as np

from .. import _native
from ..cameras import CameraModel
from ..optics import circle_of_confusion_mm
from ..units import mm_from_m

__all__ = ["MAX_PINHOLE_SPP", "METHOD", "SUB_ROWS", "pinhole_pass_spp", "signed_coc_px", "depth_layers", "spread"]

MAX_PINHOLE_SPP = 16
"""The pinhole pass draws at most min(spp, 16) samples per pixel. It samples only the
film (antialiasing), not the lens: 16 stratified film samples resolve an
edge to 1/16 of a pixel's area, and the spread then averages a defocused
pixel with its neighbours. A requested spp above 16 is recorded but not drawn
(``metadata["postfilter"]["pinhole_spp"]`` says what was). Fewer everywhere are
not enough: on showcase the postfilter's relative RMSE against the converged
thin lens is 2.0 % with 16, 3.0 % with 8 and 4.2 % with 4 (edge band: 3.4,
5.3, 7.1 %; bench/study_pinhole_spp.py). By default the pass draws 16 only
where a first pass of 2 shows an edge (:mod:`lenscompare.postfilter.refine`;
about 6.6 a pixel on average on showcase, at the uniform pass's error);
drawing fewer where the blur averages a pixel with its neighbours
(:func:`~lenscompare.postfilter.pinhole_sample_counts`, opt-in) is measurably
less accurate (bench/study_pinhole_counts.py)."""

METHOD = "scatter: per-pixel eq.-5 kernel, depth layers composited back to front over hole-filled layers"
SUB_ROWS = 4          # heights per row at which a kernel is integrated
LINEAR_LAYERS_PX = 10.0  # layers 1 px wide up to this diameter, then 10 % wide


def pinhole_pass_spp(spp: int) -> int:
    """Film samples the pinhole pass draws for a requested ``spp``: min(spp, 16)."""
    return max(1, min(int(spp), MAX_PINHOLE_SPP))


def signed_coc_px(depth_m: np.ndarray, camera: CameraModel, *, pixel_pitch_mm: float | None = None) -> np.ndarray:
    """Blur-disk diameter (eq. 5) of each depth, in pixels, signed: > 0 behind
    the plane of focus, < 0 in front of it.

    Parameters
    ----------
    depth_m : ndarray
        Depth along the view axis, m (``inf``: the background).
    camera : CameraModel
        The thin lens imitated: focal length, f-number (aperture), focus.
    pixel_pitch_mm : float, optional
        Default the camera's; another pitch gives the same diameters in other pixels.

    Returns
    -------
    ndarray, float32
        Finite everywhere: the background gets the blur of a point at
        infinity; a depth at or inside the focal length gets eq. 5's finite
        value, and any diameter is capped at twice the image diagonal (a
        wash over the whole frame either way).
    """
    pitch = camera.pixel_pitch_mm if pixel_pitch_mm is None else pixel_pitch_mm
    depth = np.asarray(depth_m, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        c = circle_of_confusion_mm(mm_from_m(depth), focus_distance_mm=camera.focus_distance_mm,
                                   focal_length_mm=camera.focal_length_mm,
                                   aperture_diameter_mm=camera.aperture_diameter_mm) / pitch
    cap = 2.0 * float(np.hypot(camera.film.width_mm, camera.film.height_mm)) / pitch
    c = np.nan_to_num(np.asarray(c, dtype=float), nan=cap, posinf=cap)
    c = np.minimum(c, cap)
    return np.where(depth > camera.focus_distance_m, c, -c).astype(np.float32)


def depth_layers(coc_px: np.ndarray) -> tuple[np.ndarray, int]:
    """Each pixel's layer, 0 the farthest, and the number of layers.

    The signed diameter grows with depth, so its bins are depth layers: 1 px
    wide up to 10 px, then 10 % of the diameter wide (a layer's pixels then
    differ in blur by less than the edge of their disks' antialiasing).
    """
    size = np.abs(coc_px.astype(float))
    stretched = np.where(size < LINEAR_LAYERS_PX, size,
                         LINEAR_LAYERS_PX * (1.0 + np.log(np.maximum(size, LINEAR_LAYERS_PX) / LINEAR_LAYERS_PX)))
    bins = np.floor(np.sign(coc_px) * stretched).astype(np.int64)
    # the rank of each bin among those present (np.unique's inverse, without its sort)
    offset = bins - bins.min()
    present = np.bincount(offset.ravel()) > 0
    rank = np.cumsum(present) - 1
    n_layers = int(rank[-1]) + 1
    return (n_layers - 1 - rank[offset]).astype(np.int32), n_layers


def spread(pixels: np.ndarray, depth_m: np.ndarray, camera: CameraModel, *,
           threads: int | None = None, coc_px: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, dict]:
    """The pinhole image with each pixel spread over its blur disk.

    Parameters
    ----------
    pixels : ndarray, float32, (H, W, 3)
        The pinhole render.
    depth_m : ndarray, (H, W)
        Its depth buffer (:func:`~lenscompare.postfilter.depth_buffer_m`).
    camera : CameraModel
        The thin lens whose defocus is imitated (its aperture's blades too).
    threads : int, optional
        Worker threads (default all cores); the image does not depend on it.
    coc_px : ndarray, float32, (H, W), optional
        :func:`signed_coc_px` of ``depth_m`` and ``camera``, when the caller has it.

    Returns
    -------
    pixels, coverage, info
        The filtered image; the composited weight each pixel received before
        normalisation (< 1 at the border and in holes); what was done
        (``method``, ``layers``, ``kernel``, ``max_coc_px``, ``seconds``).
    """
    start = time.perf_counter()
    coc = signed_coc_px(depth_m, camera) if coc_px is None else np.asarray(coc_px, dtype=np.float32)
    layer, n_layers = depth_layers(coc)
    out = np.empty_like(pixels, dtype=np.float32)
    coverage = np.empty(coc.shape, dtype=np.float32)
    threads = min(int(threads or 0), os.cpu_count() or 1)
    _native.scatter_depth_of_field(np.ascontiguousarray(pixels, dtype=np.float32), coc, layer, n_layers,
                                   camera.aperture_blades, camera.aperture_rotation_deg, SUB_ROWS, threads, out,
                                   coverage)
    info = {"method": METHOD, "layers": n_layers,
            "kernel": f"{camera.aperture_blades}-gon" if camera.aperture_blades else "disk",
            "max_coc_px": float(np.abs(coc).max()), "seconds": time.perf_counter() - start}
    return out, coverage, info
