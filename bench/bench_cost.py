"""The cost study at fixed small settings, so performance can be followed over time.

Prints one JSON object: for showcase.toml at quarter resolution, every model and
sampler at 1-64 spp: seconds, samples/s and relative RMSE against a cached
converged reference; the time to reach 1 % relative RMSE; POV-Ray's row.

``--timing-repeats N`` renders the grid N times and times each point by its fastest
round (``lenscompare cost --timing-repeats``), for a machine whose speed varies.

Usage: python bench/bench_cost.py [--threads T] [--no-povray] [--timing-repeats N]
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
from pathlib import Path

from lenscompare.cost import CostSettings, run_cost_study
from lenscompare.scene import load_scene

SCENE = Path(__file__).resolve().parent.parent / "reference_scenes" / "showcase.toml"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--threads", type=int, default=os.cpu_count())
    parser.add_argument("--no-povray", action="store_true")
    parser.add_argument("--timing-repeats", type=int, default=1)
    args = parser.parse_args()
    settings = CostSettings(quick=True, threads=args.threads, povray=not args.no_povray,
                            timing_repeats=args.timing_repeats)
    with tempfile.TemporaryDirectory() as out:
        results = run_cost_study([load_scene(SCENE)], out, settings, progress=False)
    study = results["scenes"]["showcase"]
    summary = {
        "benchmark": "cost_study",
        "scene": "showcase",
        "resolution": study["resolution"],
        "threads": args.threads,
        "timing_repeats": args.timing_repeats,
        "spp_values": results["settings"]["spp_values"],
        "seconds_to_1_percent": {
            model: {sampler: s["seconds_to_1_percent"] for sampler, s in series.items()}
            for model, series in study["models"].items()},
        "slopes": {model: {sampler: s["slope"] for sampler, s in series.items()}
                   for model, series in study["models"].items()},
        "model_error_vs_lens": study["model_error_vs_lens"],
        "povray_seconds_to_1_percent": (study["povray"] or {}).get("seconds_to_1_percent"),
        "points": {model: {sampler: s["points"] for sampler, s in series.items()}
                   for model, series in study["models"].items()},
        "findings": results["findings"],
        "total_seconds": results["total_seconds"],
    }
    print(json.dumps(summary, indent=2))


if __name__ == "__main__":
    main()
