"""Camera samples in the render loop's order, for the benchmarks that time camera rays alone.

The render walks 16-pixel tiles row by row, and within a tile each pixel's
samples in a row, so a camera batch holds one or two pixels' samples and the
lens system's pupil tables stay cached; camera-only timings that walk the film
in another order would not measure what a render pays.
"""

from __future__ import annotations

import numpy as np

TILE_PX = 16


def render_order_samples(width_px, height_px, *, samples_per_pixel, seed):
    """Raster points (float32, pixels) tile by tile, pixel by pixel, samples_per_pixel in a row, each
    jittered in its pixel; lens samples (float32) uniform in the unit square. Both from ``seed``."""
    rng = np.random.default_rng(seed)
    pixels = [(tx + x, ty + y)
              for ty in range(0, height_px, TILE_PX) for tx in range(0, width_px, TILE_PX)
              for y in range(min(TILE_PX, height_px - ty)) for x in range(min(TILE_PX, width_px - tx))]
    corners = np.repeat(np.array(pixels, float), samples_per_pixel, axis=0)
    raster = (corners + rng.random(corners.shape)).astype(np.float32)
    lens = rng.random(corners.shape).astype(np.float32)
    return raster, lens
