"""Lens system against pinhole in samples per CPU-second: the ratio a loaded machine disturbs least.

bench_peers.py and bench_lens.py time renders by the wall clock, which other
work on a shared machine stretches unevenly. Here each render's cost is this
process's CPU time (all threads), and the scene set-up (Embree BVH, exit-pupil
rings, calibration) is taken out by subtracting a 1-spp render of the same
scene: the rest is the render loop's cost for spp - 1 samples per pixel. The
models alternate, ``--repeat`` rounds, each keeping its best.

Models: ``pinhole``, ``thin`` and ``lens`` (Double Gauss 50 mm at full
aperture, as bench_peers.py). Prints one JSON object. Not a test. Usage::

    flock /tmp/bench.lock .venv/bin/python bench/bench_lens_cpu.py [--scene showcase] [--spp 64] [--threads 1]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from lenscompare.render import render  # noqa: E402
from lenscompare.scene import load_scene  # noqa: E402

LENS = "dgauss.50mm"
GOAL_LENS_OVER_PINHOLE = 0.85


def cpu_seconds(scene, model, spp, threads):
    start = time.process_time()
    render(scene, model=model, spp=spp, threads=threads, progress=False)
    return time.process_time() - start


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scene", default="showcase", help="name in reference_scenes/")
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--resolution", type=int, nargs=2, default=(240, 160), metavar=("W", "H"))
    parser.add_argument("--repeat", type=int, default=3, help="alternating rounds; each model keeps its best")
    args = parser.parse_args()

    scene = load_scene(ROOT / "reference_scenes" / f"{args.scene}.toml").with_camera(resolution=tuple(args.resolution))
    scenes = {"pinhole": scene, "thin": scene, "lens": scene.with_camera(lens=LENS, f_number=None)}
    for model, s in scenes.items():
        cpu_seconds(s, model, 1, args.threads)  # first render of each: caches and pools warm
    best = {model: float("inf") for model in scenes}
    for _ in range(args.repeat):
        for model, s in scenes.items():
            loop = cpu_seconds(s, model, args.spp, args.threads) - cpu_seconds(s, model, 1, args.threads)
            best[model] = min(best[model], loop)
    samples = args.resolution[0] * args.resolution[1] * (args.spp - 1)
    per_cpu_second = {model: samples / seconds for model, seconds in best.items()}
    print(json.dumps({
        "benchmark": "lens system against pinhole, samples per CPU-second of the render loop",
        "scene": args.scene,
        "lens": LENS,
        "spp": args.spp,
        "threads": args.threads,
        "resolution": list(args.resolution),
        "repeat": args.repeat,
        "samples_per_cpu_second": per_cpu_second,
        "lens_over_pinhole": per_cpu_second["lens"] / per_cpu_second["pinhole"],
        "thin_over_pinhole": per_cpu_second["thin"] / per_cpu_second["pinhole"],
        "goal_lens_over_pinhole": GOAL_LENS_OVER_PINHOLE,
    }, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
