"""The cost study's composite rows (issue 14): what each part of a composite
costs, the composite's time to 1 % relative RMSE against its own converged
image, and its error against the full lens system's converged image.

The composite is the planner's (or, when the planner picks no composite, the
one of every part the lens allows). Rendered in this process, not as cluster
tasks: a handful of small renders beside the study's grid.
"""

from __future__ import annotations

import time

import numpy as np

from ..cameras import COMPOSITE_EFFECTS, camera_for
from ..errors import InputError
from ..metrics import relative_rmse, ssim
from ..plan import plan_scene
from ..render import render
from ..scene import Scene
from .references import converged_reference

__all__ = ["composite_study", "PART_SPP"]

PART_SPP = 16  # each part timed alone at this sample count


def composite_study(scene: Scene, settings, lens_reference: np.ndarray, *, time_to_error, target: float) -> dict | None:
    """The composite's rows for one scene, or None without a lens (an
    ``error`` entry when the composite cannot stand in for it)."""
    if scene.camera.lens is None:
        return None
    plan = plan_scene(scene, measure_costs=False)
    effects = plan.composite_effects or COMPOSITE_EFFECTS
    start = time.perf_counter()
    try:
        camera_for(scene, "composite", effects=effects)  # traces (and memoises) the maps
    except InputError as error:
        return {"effects": list(effects), "error": error.problem}
    maps_seconds = time.perf_counter() - start
    parts = {part: render(scene, effects=(part,), spp=PART_SPP, seed=0, threads=settings.threads,
                          progress=False).metadata["seconds"] for part in effects}
    composite = scene.with_render(effects=effects)
    reference, _ = converged_reference(composite, "composite", spp=settings.reference_spp, cache_dir=settings.cache_dir,
                                       threads=settings.threads)
    points = []
    for spp in settings.spp_values:
        image = render(composite, model="composite", spp=spp, sampler="jittered", seed=0, threads=settings.threads,
                       progress=False)
        points.append({"spp": spp, "seconds": image.metadata["seconds"],
                       "relative_rmse": relative_rmse(reference.pixels, image.pixels)})
    data_range = float(lens_reference.max() - lens_reference.min()) or 1.0
    return {"effects": list(effects), "planned": plan.model == "composite", "maps_seconds": maps_seconds,
            "part_seconds": {"spp": PART_SPP, **parts}, "points": points,
            "seconds_to_1_percent": time_to_error(points, target),
            "error_vs_lens": {"relative_rmse": relative_rmse(lens_reference, reference.pixels),
                              "ssim": ssim(lens_reference, reference.pixels, data_range=data_range)}}
