"""The pinhole pass in two steps: a few film samples everywhere, the full
count only where those show something to antialias.

The pinhole pass samples only the film, and on a scene of diffuse surfaces
under point lights a film sample's colour varies across a pixel only where
an edge crosses it (a silhouette, a texture or shadow boundary, a lamp
smaller than the pixel). Inside a smooth region a few stratified samples
already give the pixel's mean; 16 more change it by far less than the noise
that remains at edges. So the pass draws ``BASE_PINHOLE_SPP`` samples in
every pixel, and redraws n = min(spp, 16), the uniform pass's count, in

- the pixels on a depth discontinuity (known before the colour pass, from the
  depth buffer: they are drawn with n at once);
- the pixels whose 3 x 3 neighbourhood shows a spread in colour, or a
  variance of the mean, above a fraction of the image's mean brightness;
  a pixel whose blur disk covers A > 1 px is averaged with about A others
  by the spread, so its thresholds are raised by sqrt(A).

A redrawn pixel draws its n samples afresh under the same seed: it is the
uniform pass's pixel bit for bit (the base samples are not reused; jittered
strata of 2 and 16 do not nest). The contrast test is the classic adaptive
antialiasing criterion (Mitchell 1987); the variance test catches an edge
that lies inside one pixel and moves no neighbour's mean.

What it costs and saves (showcase, 360 x 240, ``bench/bench_postfilter.py``):
about 40 % of the uniform pass's samples for an error against the converged
thin lens within a few hundredths of a percent of the uniform pass's.

References
----------
.. [1] D. P. Mitchell, "Generating antialiased images at low sampling
   densities", SIGGRAPH 1987, 65-72, doi:10.1145/37402.37410.
"""

from __future__ import annotations

import numpy as np
from .edges import DEPTH_JUMP

__all__ = ["BASE_PINHOLE_SPP", "CONTRAST_FRACTION", "NOISE_FRACTION", "RULE", "silhouette_pixels", "refine_pixels"]

BASE_PINHOLE_SPP = 2
"""Film samples every pixel draws first. On showcase (2 threads, error against the
converged thin lens): 1 sample misses edges the contrast test then cannot see
(2.15 % against the uniform pass's 2.06 %); 4 draw a quarter more in all (8.3
against 6.6 a pixel) for 0.01 pp less error (2.06 against 2.075 %)."""
CONTRAST_FRACTION = 0.1
"""A pixel is redrawn when the colour spread of its 3 x 3 neighbourhood (any
channel) exceeds this fraction of the image's mean, times sqrt(blur area)."""
NOISE_FRACTION = 0.01
"""... or when the largest standard deviation of the mean in its 3 x 3
neighbourhood exceeds this fraction of the image's mean, times sqrt(blur area)."""
RULE = (f"{BASE_PINHOLE_SPP} film samples everywhere; n = min(spp, 16) on depth discontinuities and where the "
        f"3x3 colour spread > {CONTRAST_FRACTION:g} or the sd of the mean > {NOISE_FRACTION:g} of the image mean "
        "(times sqrt(max(1, blur area px)))")


def silhouette_pixels(depth_m: np.ndarray) -> np.ndarray:
    """Pixels with a relative depth step over ``DEPTH_JUMP`` to a 4-neighbour
    (bool; ``inf`` against a finite depth is a step, ``inf`` against ``inf`` none),
    as :func:`~lenscompare.postfilter.edges.occlusion_edges` counts them."""
    depth = np.asarray(depth_m, dtype=np.float32)
    out = np.zeros(depth.shape, dtype=bool)
    with np.errstate(invalid="ignore"):
        for a, b in (((slice(1, None), slice(None)), (slice(None, -1), slice(None))),
                     ((slice(None), slice(1, None)), (slice(None), slice(None, -1)))):
            step = np.abs(depth[a] - depth[b]) > DEPTH_JUMP * np.minimum(depth[a], depth[b])
            out[a] |= step
            out[b] |= step
    return out


def _neighbourhood(values: np.ndarray, op) -> np.ndarray:
    """``op`` (np.maximum or np.minimum) over each pixel's 3 x 3 neighbourhood,
    edges repeated (separable: rows, then columns)."""
    padded = np.pad(values, [(1, 1), (1, 1)] + [(0, 0)] * (values.ndim - 2), mode="edge")
    rows = op(op(padded[:-2], padded[1:-1]), padded[2:])
    return op(op(rows[:, :-2], rows[:, 1:-1]), rows[:, 2:])


def refine_pixels(first_pixels: np.ndarray, first_variance: np.ndarray, coc_px: np.ndarray,
                  drawn_full: np.ndarray) -> np.ndarray:
    """The pixels of the first pass that take the full count.

    Parameters
    ----------
    first_pixels : ndarray, float32, (H, W, 3)
        The first pass (``BASE_PINHOLE_SPP`` samples; n where ``drawn_full``).
    first_variance : ndarray, (H, W)
        Its variance of each pixel's mean, summed over the channels.
    coc_px : ndarray, (H, W)
        Signed blur-disk diameter, px.
    drawn_full : ndarray, bool, (H, W)
        Pixels the first pass already drew with n (never redrawn).

    Returns
    -------
    ndarray, bool, (H, W)
    """
    mean = float(np.mean(first_pixels))
    if not mean > 0.0:
        return ~drawn_full  # a black first pass tells nothing: draw everything
    spread = (_neighbourhood(first_pixels, np.maximum) - _neighbourhood(first_pixels, np.minimum)).max(axis=2)
    noise = _neighbourhood(np.sqrt(np.maximum(first_variance, 0.0) / 3.0), np.maximum)
    averaged = np.sqrt(np.maximum(np.float32(np.pi / 4.0) * np.square(coc_px, dtype=np.float32), 1.0))
    busy = (spread > CONTRAST_FRACTION * mean * averaged) | (noise > NOISE_FRACTION * mean * averaged)
    return busy & ~drawn_full
