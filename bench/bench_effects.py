"""Effects as parts: the time ``--model auto`` (a composite) needs to reach 1 %
relative RMSE against its own converged image, against the time the full lens
system needs to do the same against its own.

Prints one JSON object: the plan, for each render the (spp, seconds, relative
RMSE) points (best of --repeats, the two renders alternating), each one's time
to 1 % (lenscompare.cost.time_to_error), their ratio (goal <= 1/3), the one-off
time to trace the composite's maps, and the composite's error against the lens
system's converged image.

Usage: python bench/bench_effects.py [--threads T] [--repeats N] [--lens L] [--f-number N]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from lenscompare.cameras import camera_for
from lenscompare.cost.references import converged_reference
from lenscompare.cost.study import time_to_error
from lenscompare.lenses import maps as lens_maps
from lenscompare.metrics import relative_rmse
from lenscompare.plan import plan_scene
from lenscompare.render import render
from lenscompare.scene import load_scene

SCENE = Path(__file__).resolve().parent.parent / "reference_scenes" / "showcase.toml"
SPP_VALUES = (1, 2, 4, 8, 16, 32, 64, 128, 256, 512)
TARGET = 0.01


def auto_against_lens(renders: dict, references: dict, spp_values, *, target: float = TARGET, repeats: int,
                      threads: int):
    """Renders ``renders`` (name -> (scene, model); "auto" and "lens") at each
    spp, alternating so both see the same machine, best of ``repeats``; each
    one's error against its own reference. Returns the best rows per name and
    spp, their points, the time to ``target`` relative RMSE per name and auto's
    over lens's."""
    best = {name: {} for name in renders}
    for _ in range(repeats):
        for spp in spp_values:
            for name, (s, model) in renders.items():
                image = render(s, model=model, spp=spp, seed=7, threads=threads, progress=False)
                seconds = image.metadata["seconds"]
                if spp not in best[name] or seconds < best[name][spp]["seconds"]:
                    best[name][spp] = {"spp": spp, "seconds": seconds,
                                       "relative_rmse": relative_rmse(references[name], image.pixels)}
    points = {name: [best[name][spp] for spp in spp_values] for name in renders}
    to_target = {name: time_to_error(points[name], target) for name in renders}
    ratio = None
    if to_target["auto"]["seconds"] and to_target["lens"]["seconds"]:
        ratio = to_target["auto"]["seconds"] / to_target["lens"]["seconds"]
    return best, points, to_target, ratio


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--lens", default="dgauss.50mm")
    parser.add_argument("--f-number", type=float, default=8.0)
    parser.add_argument("--reference-spp", type=int, default=4096)
    args = parser.parse_args()

    scene = load_scene(SCENE).with_camera(lens=args.lens, f_number=args.f_number, resolution=(180, 120))
    plan = plan_scene(scene, measure_costs=False)
    lens_maps._CACHE.clear()  # time the maps from scratch
    start = time.perf_counter()
    camera_for(scene, "composite", effects=plan.composite_effects) if plan.model == "composite" else None
    maps_seconds = time.perf_counter() - start
    auto = scene.with_render(effects=plan.composite_effects) if plan.model == "composite" else scene
    renders = {"auto": (auto, plan.model), "lens": (scene, "lens")}
    references = {name: converged_reference(s, model, spp=args.reference_spp, threads=args.threads)[0].pixels
                  for name, (s, model) in renders.items()}

    best, points, to_target, ratio = auto_against_lens(renders, references, SPP_VALUES, repeats=args.repeats,
                                                       threads=args.threads)
    print(json.dumps({
        "benchmark": "effects_as_parts",
        "scene": f"showcase at 180x120, {args.lens} f/{args.f_number:g}",
        "threads": args.threads, "repeats": args.repeats, "reference_spp": args.reference_spp,
        "plan": {"model": plan.model, "simulated": list(plan.simulated),
                 "needed": [name for name, needed in plan.needed.items() if needed]},
        "maps_seconds": maps_seconds,
        "seconds_to_1_percent": to_target,
        "ratio_auto_over_lens": ratio,
        "goal_ratio": 1 / 3,
        "auto_error_vs_lens_reference": relative_rmse(references["lens"], references["auto"]),
        "points": points,
    }, indent=2))


if __name__ == "__main__":
    main()
