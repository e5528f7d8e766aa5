"""The lens system's rays from a table (``[render] lens_rays = "table"``).

The native camera traces rays once at the nodes of a grid per exit-pupil ring
and interpolates them per sample (``native/src/lens/lens_ray_table.h``). How
far the interpolated rays stray depends on the lens: a few thousandths of a
pixel for the shipped lenses at the coarsest grid, whole pixels for a strongly
aberrated ball-like singlet at any grid. So the table is checked against the
trace before a render uses it, and refined or refused: the render then traces.
"""

from __future__ import annotations

import numpy as np

from .._native import diagnostics
from .lens import LensSystemCamera

# Cells per exit-pupil ring (radially in the square root of the pupil sample,
# around), coarsest first: a finer grid is tried only when the coarser misses
# the tolerance. 32 x 128 is 8.7 MB (half of each ring's pupil, mirrored); past it the render traces.
TABLE_CELLS = ((16, 64), (32, 128))
# The largest direction error allowed, 99.9th percentile, in pixels' angles
# (film pixel over focal length). Shipped lenses at 16 x 64: Double Gauss
# 0.018, wide angle 0.032, telephoto 0.034, fisheye 0.015.
TOLERANCE_PX = 0.05
# And the light: the samples passing one way only (the rims' sliver: at most
# 0.36 % measured, f/1000) and the weight sum against the traced (at most
# 0.19 % off, the fisheye) must stay within these.
ONE_WAY_TOLERANCE = 0.01
WEIGHT_SUM_TOLERANCE = 0.005
CHECK_SAMPLES = 1 << 15


def use_ray_table(camera: LensSystemCamera, native, *, tolerance_px: float = TOLERANCE_PX,
                  check_samples: int = CHECK_SAMPLES) -> dict:
    """Give ``native`` (``camera.native()``) the coarsest table within tolerance.

    Parameters
    ----------
    camera : LensSystemCamera
        The camera value (its film and focal length set the pixel's angle).
    native : lenscompare._native.LensSystemCamera
        Its native camera (a table it has already is dropped first).
    tolerance_px : float, optional
        The largest 99.9th-percentile direction error, in pixels' angles
        (besides, at most :data:`ONE_WAY_TOLERANCE` of the samples may pass
        one way only and the weight sum must be within
        :data:`WEIGHT_SUM_TOLERANCE` of the traced).
    check_samples : int, optional
        Film and pupil samples (uniform, a fixed seed) traced both ways.

    Returns
    -------
    dict
        For the image's metadata: ``from`` (``"table"`` or ``"traced"``),
        the cells tried last, and the measured error (``p999_error_px``,
        ``passing_one_way_only``, ``weight_sum_over_traced``);
        a refused table leaves ``native`` tracing. A bladed stop is refused
        at once (``reason``): the table holds one film azimuth's rays and
        turns them, which only a round lens allows.
    """
    if native.uses_ray_table:  # the check compares with the trace
        native.use_ray_table(0, 0)
    if camera.aperture_blades:
        return {"from": "traced", "reason": f"a {camera.aperture_blades}-blade stop is not round: a film point's "
                                            "rays are not the rotated rays of one film azimuth, which the table holds"}
    width, height = camera.film.width_px, camera.film.height_px
    rng = np.random.default_rng(0)
    raster = np.column_stack([rng.uniform(0, width, check_samples),
                              rng.uniform(0, height, check_samples)]).astype(np.float32)
    lens = rng.uniform(0, 1, (check_samples, 2)).astype(np.float32)
    _, *traced = batch_rays(native, raster, lens)
    pixel_angle = (camera.film.width_mm / width) / camera.focal_length_mm
    # The grids tried without their tile pencils (the traced rays' stay), which
    # are measured once for the grid kept.
    for radial_cells, around_cells in TABLE_CELLS:
        native.use_ray_table(radial_cells, around_cells, measure_pencils=False)
        _, *table = batch_rays(native, raster, lens)
        both = (table[1] > 0) & (traced[1] > 0)
        error_px = np.linalg.norm(table[0][both] - traced[0][both], axis=1) / pixel_angle
        p999 = float(np.percentile(error_px, 99.9)) if error_px.size else 0.0
        one_way = float(np.mean((table[1] > 0) != (traced[1] > 0)))
        weight_ratio = float(table[1].sum() / traced[1].sum()) if traced[1].sum() > 0 else 1.0
        info = {"radial_cells": radial_cells, "around_cells": around_cells, "p999_error_px": p999,
                "tolerance_px": tolerance_px, "passing_one_way_only": one_way,
                "weight_sum_over_traced": weight_ratio}
        if (p999 <= tolerance_px and one_way <= ONE_WAY_TOLERANCE
                and abs(weight_ratio - 1.0) <= WEIGHT_SUM_TOLERANCE):
            diagnostics.set_lens_pencils(native, "measured")  # the kept grid's rays' pencils
            return {"from": "table", **info}
    native.use_ray_table(0, 0, measure_pencils=False)  # the traced rays' pencils never left
    return {"from": "traced", **info}


def batch_rays(native, raster_px: np.ndarray, lens: np.ndarray):
    """(origins, directions, weights) of the rays the render's packets take
    from the native lens camera (float, the table's where it has one) for
    these raster positions and lens samples (float32, shape (n, 2)), widened
    to float64; weight 0: blocked."""
    origin, direction = np.zeros((len(raster_px), 3), np.float32), np.zeros((len(raster_px), 3), np.float32)
    weight = np.zeros(len(raster_px), np.float32)
    diagnostics.generate_lens_ray_rows(native, raster_px, lens, origin, direction, weight)
    return origin.astype(np.float64), direction.astype(np.float64), weight
