"""Time saved by the planner's composite at equal spp and at equal noise.

Renders a scene (default the shipped far_landscape, whose plan is the composite of
distortion and vignetting) through the lens system and through the plan's composite,
alternating, best of N, and prints JSON: seconds at equal spp, the mean per-pixel
variance of each image's mean, and the composite's time scaled to the lens system's
noise (Monte Carlo variance falls as 1/spp, so time x variance ratio).

Usage: python bench/bench_equal_noise.py [SCENE] [--spp N] [--threads T] [--repeats N]
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from lenscompare.plan import plan_scene
from lenscompare.reference_scenes import find_scene
from lenscompare.render import render
from lenscompare.scene import load_scene


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?", default="far_landscape")
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    scene = load_scene(find_scene(args.scene))
    plan = plan_scene(scene, measure_costs=False)
    if plan.model != "composite":
        raise SystemExit(f"{args.scene}: the plan is {plan.model}, not a composite")
    runs = {"lens": [], "composite": []}
    for _ in range(args.repeats):
        for model, effects in (("lens", None), ("composite", plan.composite_effects)):
            image = render(scene, model=model, effects=effects, spp=args.spp, threads=args.threads, progress=False)
            runs[model].append((image.metadata["seconds"], float(np.mean(image.variance))))
    best = {m: min(r) for m, r in runs.items()}
    ratio = best["composite"][1] / best["lens"][1]
    print(json.dumps({
        "benchmark": "equal_noise", "scene": args.scene, "spp": args.spp, "threads": args.threads,
        "composite_effects": list(plan.composite_effects), "resolution": list(scene.camera.resolution),
        "seconds": {m: b[0] for m, b in best.items()},
        "mean_variance_of_mean": {m: b[1] for m, b in best.items()},
        "variance_ratio_composite_over_lens": ratio,
        "composite_seconds_at_lens_noise": best["composite"][0] * ratio,
        "speedup_at_equal_noise": best["lens"][0] / (best["composite"][0] * ratio),
    }, indent=2))


if __name__ == "__main__":
    main()
