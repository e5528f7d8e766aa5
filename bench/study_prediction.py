"""Prediction study (issue 14): each effect's size as the planner predicts it
from the scene alone, against its size measured on full lens-system renders.

Scenes: the four reference scenes the report measures (blur_disks, dot_grid,
flat_field, showcase; prepared as the report prepares them: through
dgauss.50mm, at an f-number it reaches), far_landscape, and the mixed-effect
scenes in lenscompare/reference_scenes/effects/. Effects: defocus,
aberrations, distortion, vignetting; how each is measured is in
lenscompare/plan/prediction.py. ``within``: predicted within 15 % of measured,
or both under the planner's tolerance (0.5 px, 2 %).

Prints one JSON object: {"rows": [{scene, effect, unit, predicted, measured,
within, detail}, ...], "within": k, "compared": n, "seconds": s}.

Usage: python bench/study_prediction.py [--spp N] [--threads T] [SCENE ...]
"""

from __future__ import annotations

import argparse
import json
import os
import time

from lenscompare.experiment import ExperimentSettings, prepare_scene
from lenscompare.plan import plan_scene
from lenscompare.plan.prediction import compare_predictions
from lenscompare.reference_scenes import find_scene, scenes_dir
from lenscompare.scene import load_scene

REFERENCE = ("blur_disks", "dot_grid", "flat_field", "showcase", "far_landscape")


def default_scenes():
    return [find_scene(name) for name in REFERENCE] + sorted((scenes_dir() / "effects").glob("*.toml"))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenes", nargs="*", help="scene files or shipped names (default: the study's set)")
    parser.add_argument("--spp", type=int, default=256)
    parser.add_argument("--threads", type=int, default=os.cpu_count())
    args = parser.parse_args()
    start = time.perf_counter()
    rows = []
    for path in [find_scene(s) for s in args.scenes] or default_scenes():
        scene, _ = prepare_scene(load_scene(path), ExperimentSettings(povray=False, mitsuba=False))
        plan = plan_scene(scene, measure_costs=False)
        rows += [c.to_json() for c in compare_predictions(scene, plan, spp=args.spp, threads=args.threads)]
    compared = [r for r in rows if r["within"] is not None]
    print(json.dumps({"rows": rows, "within": sum(r["within"] for r in compared), "compared": len(compared),
                      "spp": args.spp, "seconds": round(time.perf_counter() - start, 1)}, indent=1))


if __name__ == "__main__":
    main()
