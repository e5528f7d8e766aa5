"""The cost study: for each model, sampler and sample count, the wall time and
the error against a converged reference; for the cheaper models, their error
against the full lens system; POV-Ray's focal blur as a row of the thin lens."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..cluster import Cluster, run_calls
from ..errors import ExternalError
from ..experiment import ExperimentSettings, prepare_scene
from ..metrics import relative_rmse, rmse, ssim
from ..plan import MODEL_ORDER, plan_scene, renders_color
from ..plan.effects import COLOR_EFFECTS
from ..povray import pov_camera, render_povray
from ..motion import samples_time
from ..povray.runner import longest_streak_px, subframes_for
from ..render import render
from ..scene import MODELS, SAMPLERS, Scene
from .composites import composite_study
from .references import converged_reference

__all__ = ["CostSettings", "study_scene", "povray_series_wanted", "time_to_error", "fitted_slope", "pareto_front"]

TARGET_RELATIVE_RMSE = 0.01


# The lens system's series with its rays interpolated from a table traced once
# ([render] lens_rays = "table"): its error, against the traced lens's
# converged image, holds the table's own besides the noise.
TABLE_SERIES = "jittered, ray table"
# The same with mirrored rays (render's lens_mirrors): the lens system's fastest path, what
# --model auto renders for a lens-system plan. Each pixel's error is the table series'; mirror
# images' errors are one error.
TABLE_MIRRORED_SERIES = "jittered, ray table, mirrored"


@dataclass(frozen=True)
class CostSettings:
    quick: bool = False
    lens: str = "dgauss.50mm"
    threads: int | None = None
    cache_dir: Path | None = None
    povray: bool = True
    samplers: tuple[str, ...] = field(default_factory=lambda: tuple(SAMPLERS))
    models: tuple[str, ...] = MODELS
    # Renders of each (model, sampler, spp) point, in rounds over the whole grid; its time is the
    # fastest round's (its image is the same every round: the same seed). More than one for a
    # machine whose speed varies between repeats, so that a slow spell does not reorder the table.
    timing_repeats: int = 1

    @property
    def timing_rounds(self) -> int:
        """Rounds over the grid: timing_repeats, and at least one."""
        return max(1, self.timing_repeats)

    @property
    def spp_values(self) -> tuple[int, ...]:
        return (1, 4, 16, 64) if self.quick else (1, 4, 16, 64, 256, 1024)

    @property
    def reference_spp(self) -> int:
        return 1024 if self.quick else 4096

    @property
    def resolution_divisor(self) -> int:
        return 4 if self.quick else 2

    @property
    def povray_spp_values(self) -> tuple[int, ...]:
        return (4, 16, 64) if self.quick else (4, 16, 64, 256)


def _error(reference: np.ndarray, image: np.ndarray) -> dict:
    return {"rmse": rmse(reference, image), "relative_rmse": relative_rmse(reference, image)}


def study_scene(scene: Scene, settings: CostSettings, *, progress=None, cluster: Cluster | None = None) -> dict:
    """Every (model, sampler, spp) render of one scene, with its cost and error.

    With a ``cluster`` the references and renders run there as tasks (each
    timed on its worker); the errors are computed here.
    """
    result = {"resolution": list(scene.camera.resolution), "models": {}, "model_error_vs_lens": {}, "povray": None,
              "references": {}}
    converged = run_calls(cluster, converged_reference,
                          [((scene, model), {"spp": settings.reference_spp, "cache_dir": settings.cache_dir})
                           for model in settings.models], threads=settings.threads)
    references = {model: ref.pixels for model, (ref, _) in zip(settings.models, converged)}
    for model, (ref, cached) in zip(settings.models, converged):
        result["references"][model] = {"spp": settings.reference_spp, "cached": cached,
                                       "seconds": ref.metadata.get("seconds")}
    grid = [(model, sampler, spp) for model in settings.models for sampler in study_series(model, settings)
            for spp in settings.spp_values]
    calls = [((scene,), _render_options(model, sampler, spp)) for model, sampler, spp in grid]
    images = dict(zip(grid, run_calls(cluster, render, calls, threads=settings.threads, progress=progress)))
    by_round = {cell: [images[cell].metadata] for cell in grid}
    rounds = settings.timing_rounds
    # Later rounds only for their times (the same seed, the same image): their pixels are dropped.
    for _ in range(rounds - 1):
        for cell, image in zip(grid, run_calls(cluster, render, calls, threads=settings.threads, progress=progress)):
            by_round[cell].append(image.metadata)
    for model in settings.models:
        series = {}
        for sampler in study_series(model, settings):
            points = []
            for spp in settings.spp_values:
                image = images[model, sampler, spp]
                fastest = min(by_round[model, sampler, spp], key=lambda m: m["seconds"])
                points.append({"spp": spp, "seconds": fastest["seconds"],
                               "samples_per_second": fastest["samples_per_second"],
                               **({"seconds_by_round": [m["seconds"] for m in by_round[model, sampler, spp]]}
                                  if rounds > 1 else {}),
                               **_error(references[model], image.pixels)})
            series[sampler] = {"points": points, "slope": fitted_slope(points),
                               "seconds_to_1_percent": time_to_error(points, TARGET_RELATIVE_RMSE)}
        result["models"][model] = series
    if "lens" in references:
        omitted = _omitted_effects(scene)
        for model in settings.models:
            if model == "lens":
                continue
            data_range = float(references["lens"].max() - references["lens"].min()) or 1.0
            result["model_error_vs_lens"][model] = {
                "relative_rmse": relative_rmse(references["lens"], references[model]),
                "ssim": ssim(references["lens"], references[model], data_range=data_range),
                # What the model leaves out, effect by effect (blur px, distortion px at
                # the corner, corner falloff %), as the planner computes them.
                "omitted_effects": omitted.get(model, {})}
        # The composite of parts, scored against the same lens-system reference.
        result["composite"] = composite_study(scene, settings, references["lens"], time_to_error=time_to_error,
                                              target=TARGET_RELATIVE_RMSE)
    if povray_series_wanted(scene, settings) and "thin" in references:
        result["povray"] = _povray_series(scene, references["thin"], settings, progress, cluster)
    elif settings.povray and "thin" in references:
        result["povray"] = {"error": "left out of a quick study: POV-Ray renders a moving scene as the mean of "
                                     "sub-frames, which costs most of the study (run without --quick)"}
    return result


def study_series(model: str, settings: CostSettings) -> tuple[str, ...]:
    """The model's series: one per sampler, and for the lens system the jittered
    sampler again with its rays from a table (:data:`TABLE_SERIES`), and from
    the table with mirrored rays (:data:`TABLE_MIRRORED_SERIES`)."""
    if model == "lens" and "jittered" in settings.samplers:
        return (*settings.samplers, TABLE_SERIES, TABLE_MIRRORED_SERIES)
    return settings.samplers


def _render_options(model: str, series: str, spp: int) -> dict:
    """render()'s keywords for one point of a series."""
    options = {"model": model, "spp": spp, "sampler": series, "seed": 0, "progress": False}
    if series in (TABLE_SERIES, TABLE_MIRRORED_SERIES):  # scored against the traced lens system's converged image
        options.update(sampler="jittered", lens_rays="table", lens_mirrors=series == TABLE_MIRRORED_SERIES)
    return options


def povray_series_wanted(scene: Scene, settings: CostSettings) -> bool:
    """Whether the study times POV-Ray on ``scene``: asked for, and not a moving
    scene in a quick study (its sub-frames would take most of the study's time)."""
    return settings.povray and not (settings.quick and samples_time(scene))


def _omitted_effects(scene: Scene) -> dict[str, dict]:
    plan = plan_scene(scene, measure_costs=False)
    rgb = not renders_color(scene)  # an RGB render of any model leaves colour out
    return {model: {name: {"magnitude": e.magnitude, "unit": e.unit}
                    for name, e in plan.effects.items()
                    if MODEL_ORDER.index(e.needed_by) > MODEL_ORDER.index(model) or (rgb and name in COLOR_EFFECTS)}
            for model in MODEL_ORDER}


def _povray_series(scene: Scene, reference: np.ndarray, settings: CostSettings, progress,
                   cluster: Cluster | None) -> dict | None:
    # A moving scene: at most one sub-frame per ray per pixel, so each point costs its spp (K
    # sub-frames of at least 1 ray each would make 4 spp cost K).
    subframes = subframes_for(longest_streak_px(scene, pov_camera(scene, "thin").camera))
    images = run_calls(cluster, render_povray, [((scene,), {"model": "thin", "spp": spp,
                                                            "time_samples": min(spp, subframes)})
                                                for spp in settings.povray_spp_values],
                       threads=settings.threads, catch=(ExternalError,), progress=progress)
    failed = next((image for image in images if isinstance(image, ExternalError)), None)
    if failed is not None:
        return {"error": str(failed)}
    points = [{"spp": spp, "seconds": image.metadata["seconds"],
               "samples_per_second": image.metadata.get("samples_per_second"), **_error(reference, image.pixels)}
              for spp, image in zip(settings.povray_spp_values, images)]
    return {"points": points, "slope": fitted_slope(points),
            "seconds_to_1_percent": time_to_error(points, TARGET_RELATIVE_RMSE)}


def fitted_slope(points: list[dict]) -> float | None:
    """Least-squares slope of log(relative RMSE) against log(spp); -0.5 is plain
    Monte Carlo, steeper is better. Points at the reference's noise floor
    (the last doubling gaining under 10 %) are left out."""
    spp = np.array([p["spp"] for p in points], dtype=float)
    err = np.array([p["relative_rmse"] for p in points], dtype=float)
    keep = np.isfinite(err) & (err > 0)
    if keep.sum() < 2:
        return None
    return float(np.polyfit(np.log(spp[keep]), np.log(err[keep]), 1)[0])


def time_to_error(points: list[dict], target: float) -> dict:
    """Seconds to reach ``target`` relative RMSE: interpolated log-log between
    the two renders that straddle it, or extrapolated along the last two
    points' slope (flagged) when no render got there."""
    pts = sorted((p["seconds"], p["relative_rmse"]) for p in points if p["relative_rmse"] > 0)
    for (t0, e0), (t1, e1) in zip(pts, pts[1:]):
        if e0 >= target >= e1 and e0 != e1:
            a = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return {"seconds": math.exp(math.log(t0) + a * (math.log(t1) - math.log(t0))), "extrapolated": False}
    if pts and pts[0][1] <= target:
        return {"seconds": pts[0][0], "extrapolated": False}
    if len(pts) >= 2:
        (t0, e0), (t1, e1) = pts[-2], pts[-1]
        if e1 < e0:
            slope = (math.log(e1) - math.log(e0)) / (math.log(t1) - math.log(t0))
            return {"seconds": math.exp(math.log(t1) + (math.log(target) - math.log(e1)) / slope),
                    "extrapolated": True}
    return {"seconds": None, "extrapolated": True}


def pareto_front(points: list[tuple[float, float, str]]) -> list[tuple[float, float, str]]:
    """Points (seconds, error, label) that no other point beats on both."""
    front, best = [], math.inf
    for t, e, label in sorted(points):
        if e < best:
            front.append((t, e, label))
            best = e
    return front


def prepared_for_cost(scene: Scene, settings: CostSettings) -> Scene:
    """The experiment's scene (lens, f-number), at the study's smaller resolution."""
    prepared, _ = prepare_scene(scene, ExperimentSettings(lens=settings.lens))
    w, h = prepared.camera.resolution
    d = settings.resolution_divisor
    while d > 1 and (w % d or h % d):
        d //= 2
    return prepared.with_camera(resolution=(w // d, h // d))
