"""Lateral colour as a composite part: the spectral composite that ``--model
auto`` picks for reference_scenes/effects/landscape_color.toml (the shipped
landscape lens at f/32, colour above tolerance, aberrations not) against the
full lens system's spectral render of the same scene.

Prints one JSON object: the plan; each render's (spp, seconds, relative RMSE
against its own converged image) points, best of --repeats with the two
renders alternating, and its time to 1 % relative RMSE
(lenscompare.cost.time_to_error); their ratio; and the composite's converged
image against the lens system's: relative RMSE, and on the dot grid
(lenscompare.metrics.lateral_color) each dot's green centroid and its
red-minus-blue radial shift, px.

Usage: python bench/bench_composite_color.py [--threads T] [--repeats N] [--reference-spp N]
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

from bench_effects import auto_against_lens  # bench/ is the script's directory
from lenscompare.cameras import camera_for
from lenscompare.cost.references import converged_reference
from lenscompare.lenses import maps as lens_maps
from lenscompare.metrics import lateral_color, match_points, relative_rmse
from lenscompare.plan import plan_scene
from lenscompare.reference_scenes import scenes_dir
from lenscompare.scene import load_scene

SCENE = scenes_dir() / "effects" / "landscape_color.toml"
SPP_VALUES = (16, 64, 256, 512)
TARGET = 0.01


def dot_agreement(lens_image: np.ndarray, composite_image: np.ndarray) -> dict:
    """Per-dot differences, composite minus lens system, px (dots matched on green)."""
    lens, ours = lateral_color(lens_image), lateral_color(composite_image)
    green_lens, green_ours = lens.centroids_px[:, 1], ours.centroids_px[:, 1]
    mine, theirs = match_points(green_ours, green_lens, max_distance_px=2.0)
    mine, theirs = np.asarray(mine, dtype=int), np.asarray(theirs, dtype=int)
    shift = ours.radial_shift_px[mine] - lens.radial_shift_px[theirs]
    outer = lens.field_radius_px[theirs] > 0.75 * lens.field_radius_px.max()
    return {
        "dots_matched": int(len(mine)),
        "green_centroid_max_px": float(np.hypot(*(green_ours[mine] - green_lens[theirs]).T).max()),
        "lateral_color_lens_outer_mean_px": float(lens.radial_shift_px[theirs][outer].mean()),
        "lateral_color_composite_outer_mean_px": float(ours.radial_shift_px[mine][outer].mean()),
        "lateral_color_difference_max_px": float(np.abs(shift).max()),
        "lateral_color_difference_rms_px": float(np.sqrt(np.mean(shift ** 2))),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--reference-spp", type=int, default=2048)
    args = parser.parse_args()

    scene = load_scene(SCENE)
    plan = plan_scene(scene, measure_costs=False)
    lens_maps._CACHE.clear()  # time the maps from scratch
    lens_maps._COLOR_CACHE.clear()
    start = time.perf_counter()
    if plan.model == "composite":
        camera_for(scene, "composite", effects=plan.composite_effects).lateral_color_map()
    maps_seconds = time.perf_counter() - start
    auto = scene.with_render(effects=plan.composite_effects) if plan.model == "composite" else scene
    renders = {"auto": (auto, plan.model), "lens": (scene, "lens")}
    references = {name: converged_reference(s, model, spp=args.reference_spp, threads=args.threads)[0].pixels
                  for name, (s, model) in renders.items()}

    best, points, to_target, ratio = auto_against_lens(renders, references, SPP_VALUES, target=TARGET,
                                                       repeats=args.repeats, threads=args.threads)
    equal_spp = {spp: best["lens"][spp]["seconds"] / best["auto"][spp]["seconds"] for spp in SPP_VALUES}
    print(json.dumps({
        "benchmark": "composite_lateral_color",
        "scene": "effects/landscape_color (landscape.125mm f/32, spectral)",
        "threads": args.threads, "repeats": args.repeats, "reference_spp": args.reference_spp,
        "plan": {"model": plan.model, "simulated": list(plan.simulated),
                 "needed": [name for name, needed in plan.needed.items() if needed],
                 "lateral_color_px": plan.effects["lateral_color"].magnitude,
                 "aberrations_px": plan.effects["aberrations"].magnitude},
        "maps_seconds": maps_seconds,
        "seconds_to_1_percent": to_target,
        "ratio_auto_over_lens": ratio,
        "speedup_at_equal_spp": equal_spp,
        "auto_error_vs_lens_reference": {
            "relative_rmse": relative_rmse(references["lens"], references["auto"]),
            **dot_agreement(references["lens"], references["auto"])},
        "points": points,
    }, indent=2))


if __name__ == "__main__":
    main()
