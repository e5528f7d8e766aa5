"""A task's measurements as table columns: scalars to plot and filter on,
and the curves they summarise as lists.

The measurements are :mod:`lenscompare.measure`'s, on one run; every column a
measurement can give is listed in :data:`MEASUREMENT_COLUMNS`, so a table has
the same columns whether a task succeeded or not (missing values are NaN or
empty).
"""

from __future__ import annotations

import math

import numpy as np

from .. import measure

__all__ = ["MEASUREMENT_COLUMNS", "SCALAR_MEASUREMENTS", "measurement_columns"]

# Column name -> (measurement, kind): "scalar" or "list" (a curve or per-object values).
MEASUREMENT_COLUMNS = {
    "distortion_percent_edge": ("distortion", "scalar"),
    "distortion_percent_max": ("distortion", "scalar"),
    "distortion_field_deg_max": ("distortion", "scalar"),
    "distortion_k1": ("distortion", "scalar"),
    "distortion_k2": ("distortion", "scalar"),
    "distortion_dots_matched": ("distortion", "scalar"),
    "distortion_field_deg": ("distortion", "list"),
    "distortion_percent": ("distortion", "list"),
    "vignetting_corner_percent": ("vignetting", "scalar"),
    "vignetting_corner_field_deg": ("vignetting", "scalar"),
    "relative_illumination_10deg": ("vignetting", "scalar"),
    "relative_illumination_20deg": ("vignetting", "scalar"),
    "vignetting_field_deg": ("vignetting", "list"),
    "relative_illumination": ("vignetting", "list"),
    "traced_field_deg": ("vignetting", "list"),
    "traced_relative_illumination": ("vignetting", "list"),
    "blur_disks_found": ("blur_disks", "scalar"),
    "blur_error_percent_mean_abs": ("blur_disks", "scalar"),
    "blur_error_percent_max_abs": ("blur_disks", "scalar"),
    "blur_depth_m": ("blur_disks", "list"),
    "blur_measured_px": ("blur_disks", "list"),
    "blur_expected_px": ("blur_disks", "list"),
}

SCALAR_MEASUREMENTS = {
    "distortion_percent_edge": ("distortion", "fitted distortion at the chart's edge, %"),
    "vignetting_corner_percent": ("vignetting", "corner illumination drop, %"),
    "blur_error_percent_mean_abs": ("blur-disk error", "mean |diameter error|, %"),
}
"""The one scalar per measurement that the plots show: its name and axis label."""


def measurement_columns(scene, run, measurements) -> dict:
    """The columns of every measurement in ``measurements`` on ``run``.

    Parameters
    ----------
    scene : Scene
        The scene as rendered.
    run : lenscompare.experiment.Run
    measurements : iterable of {'distortion', 'vignetting', 'blur_disks'}
    """
    columns = {}
    for name in measurements:
        columns.update(_MEASURE[name](scene, run))
    return columns


def _distortion(scene, run) -> dict:
    found = measure.measure_distortion(scene, [run])["renders"][run.label]
    if found is None:  # fewer than three dots off the axis: nothing to fit
        return {"distortion_dots_matched": 0}
    percent = np.asarray(found["distortion_percent"], dtype=float)
    field = np.asarray(found["field_deg"], dtype=float)
    largest = int(np.nanargmax(np.abs(percent)))
    # The k1/k2 fit (radius normalised to the film's half-diagonal) at the
    # widest matched dot: steadier than any one dot's centroid.
    camera = run.image.camera
    rho = math.tan(math.radians(field.max())) * camera.image_scale_mm / camera.film.half_diagonal_mm
    edge = 100.0 * (found["k1"] * rho ** 2 + found["k2"] * rho ** 4)
    return {"distortion_percent_edge": edge, "distortion_percent_max": float(percent[largest]),
            "distortion_field_deg_max": float(field.max()),
            "distortion_k1": found["k1"], "distortion_k2": found["k2"],
            "distortion_dots_matched": found["dots_matched"],
            "distortion_field_deg": field.tolist(), "distortion_percent": percent.tolist()}


def _vignetting(scene, run) -> dict:
    found = measure.measure_vignetting(scene, [run])["renders"][run.label]
    field = np.asarray(found["field_deg"], dtype=float)
    ri = np.asarray(found["relative_illumination"], dtype=float)
    known = np.isfinite(ri)
    traced = found.get("traced", {"field_deg": [], "relative_illumination": []})
    return {"vignetting_corner_percent": 100.0 * (1.0 - float(ri[known][-1])),
            "vignetting_corner_field_deg": float(field[known][-1]),
            "relative_illumination_10deg": found["at"].get("10_deg", math.nan),
            "relative_illumination_20deg": found["at"].get("20_deg", math.nan),
            "vignetting_field_deg": field.tolist(), "relative_illumination": ri.tolist(),
            "traced_field_deg": list(traced["field_deg"]),
            "traced_relative_illumination": list(traced["relative_illumination"])}


def _blur_disks(scene, run) -> dict:
    rows = [r for r in measure.measure_blur_disks(scene, [run])["renders"][run.label] if r is not None]
    errors = np.array([r["error_percent"] for r in rows if r["error_percent"] is not None], dtype=float)
    return {"blur_disks_found": len(rows),
            "blur_error_percent_mean_abs": float(np.mean(np.abs(errors))) if errors.size else math.nan,
            "blur_error_percent_max_abs": float(np.max(np.abs(errors))) if errors.size else math.nan,
            "blur_depth_m": [r["depth_m"] for r in rows], "blur_measured_px": [r["measured_px"] for r in rows],
            "blur_expected_px": [r["expected_px"] for r in rows]}


_MEASURE = {"distortion": _distortion, "vignetting": _vignetting, "blur_disks": _blur_disks}
