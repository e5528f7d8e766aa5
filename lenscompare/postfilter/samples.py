"""How many pinhole samples each pixel needs, from its blur disk.

The spread averages each pixel with the others its blur disk reaches: a
pixel spread over a disk of area A = pi (c/2)^2 px lands, divided by about
A, on about A output pixels, each of which gathers about A input pixels'
worth of independent samples (the drawn kernels' 1 / sum of w^2 is A or a
little more from 1 px up). The variance of a pixel's own film-sampling
noise is then averaged down by about A. It does not grow as 1/n when n
falls, though: stratified samples converge faster, as n^-p with p from
1.5 (an edge across the pixel) to 2 (smooth); on showcase a uniform pass
of 4, 8 and 16 samples gives noise variances in the ratio 7.7 : 3.4 : 1
(bench/study_pinhole_spp.py: p = 1.78). So a pixel may draw n / A^(1/p)
samples; with p = 2, the conservative end, ``ceil(n / sqrt(max(1, A)))``,
never below ``MIN_PINHOLE_SPP``. (n / A, tried first, raised showcase's
whole-frame error against the converged thin lens from 2.02 to 2.41 %:
bench/study_pinhole_counts.py.)

What it costs: n / sqrt(A) still raises showcase's whole-frame error from
2.02 to 2.24 % (f/1.4 near focus: 1.48 to 1.79 %), far beyond the
seed-to-seed spread (0.02 %). The spread already averages a blurred
pixel's noise with the full n; fewer samples there bring its output noise
up towards a sharp pixel's rather than keeping today's. So
:func:`lenscompare.render.render` uses these counts only when asked
(``postfilter_per_pixel_spp=True``). Spent this way, the same samples still
beat a uniform pass of their mean (2.24 against 2.44 %).

Two kinds of pixel keep all n:

- a pixel within its blur radius + 1 px of a depth discontinuity (relative
  step over ``DEPTH_JUMP`` to a 4-neighbour): there the layers' occlusion
  and the hole filling cut the averaging short (the pixels behind a sharp
  foreground gather from one side only), and the silhouette pixel's own
  antialiasing is what the spread carries over the edge;
- a pixel with a blur under 1.13 px across (A < 1): nothing averages it.

The floor of 4: a 2 x 2 stratified pixel still integrates a texture edge
across it to a quarter of its area, where 1 or 2 samples would leave the
edge's position in the pixel to chance.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import ndimage

from .blur import pinhole_pass_spp
from .edges import DEPTH_JUMP, _neighbour_jumps

__all__ = ["MIN_PINHOLE_SPP", "RULE", "pinhole_sample_counts"]

MIN_PINHOLE_SPP = 4
RULE = ("ceil(n / sqrt(max(1, pi (c/2)^2))) film samples, at least 4, n = min(spp, 16); "
        "n within c/2 + 1 px of a depth discontinuity")


def pinhole_sample_counts(coc_px: np.ndarray, depth_m: np.ndarray, spp: int, *,
                          depth_pixel_px: float = 1.0) -> np.ndarray:
    """Each pixel's pinhole film samples.

    Parameters
    ----------
    coc_px : ndarray, (H, W)
        Signed blur-disk diameter, px (:func:`~lenscompare.postfilter.signed_coc_px`).
    depth_m : ndarray, (H, W)
        The depth buffer it came from (for the discontinuities).
    spp : int
        The requested samples per pixel; n = :func:`pinhole_pass_spp` (spp).
    depth_pixel_px : float, optional
        The depth buffer's pixel in the film's pixels (the planner's
        low-resolution buffer: > 1); distances to a discontinuity scale by it.

    Returns
    -------
    ndarray, uint32, (H, W)
        ``ceil(n / sqrt(max(1, pi (c/2)^2)))`` clipped to [min(4, n), n]; n within
        c/2 + 1 px of a depth discontinuity.
    """
    n = pinhole_pass_spp(spp)
    radius_px = np.abs(np.asarray(coc_px, dtype=float)) / 2.0
    area_px = math.pi * radius_px ** 2
    # 1e-9: an area that is an exact divisor of n is not rounded up by float error
    counts = np.ceil(n / np.sqrt(np.maximum(area_px, 1.0)) - 1e-9)
    counts = np.clip(counts, min(MIN_PINHOLE_SPP, n), n)
    jumps, _ = _neighbour_jumps(depth_m, np.zeros_like(radius_px))
    edges = jumps > DEPTH_JUMP
    if edges.any():
        near_edge = ndimage.distance_transform_edt(~edges) * depth_pixel_px <= radius_px + 1.0
        counts = np.where(near_edge, n, counts)
    return counts.astype(np.uint32)

