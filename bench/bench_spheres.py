"""Still spheres: the render's own test (native sphere_lanes.cpp) against Embree's, in CPU seconds.

Each scene renders twice per round in a process of its own, once with the
own test and once with ``LENSCOMPARE_MAX_OWN_SPHERES=0`` (Embree intersects
the spheres, as before the own test); rounds alternate and each keeps its
best. The own runs lift the render's limit of 32 spheres to see past it.
Scenes: lit_showcase (5 spheres), lit_showcase without its spheres (what
spheres cost at all) and lit_showcase's floor and wall with n spheres
of radius 0.2 m on it (where the own test's cost, one test per sphere per
ray, meets Embree's BVH). Thin lens, 360 x 240, 64 spp, 2 threads.
Prints one JSON object. Not a test. Usage::

    flock /tmp/bench.lock .venv/bin/python bench/bench_spheres.py [--repeat 3] [--counts 5,16,32,48,64,96]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LIT = ROOT / "reference_scenes" / "lit_showcase.toml"

TIME = """
import sys, time
from lenscompare.render import render
from lenscompare.scene import load_scene
scene = load_scene(sys.argv[1])
start = time.process_time()
render(scene, model="thin", spp=64, threads=2, progress=False)
print(time.process_time() - start)
"""


def floor_of_spheres(n: int) -> str:
    """lit_showcase's text with its spheres replaced by n on a grid, 8 to a row."""
    blocks = LIT.read_text(encoding="utf-8").split("[[objects]]")
    text = "[[objects]]".join([blocks[0]] + [b for b in blocks[1:] if 'type = "sphere"' not in b])
    rows = max(1, (n + 7) // 8)
    for k in range(n):
        x = -2.5 + 5.0 * ((k % 8) + 0.5) / 8
        z = 1.5 + 6.0 * ((k // 8) + 0.5) / rows
        material = ("red", "blue", "white")[k % 3]
        text += f'\n[[objects]]\ntype = "sphere"\ncenter = [{x:.3f}, 0.2, {z:.3f}]\nradius = 0.2\nmaterial = "{material}"\n'
    return text


def cpu_seconds(scene: Path, *, own: bool) -> float:
    # own: every still sphere, past the render's limit too (the crossover is what this measures)
    env = dict(os.environ, LENSCOMPARE_MAX_OWN_SPHERES="1000000" if own else "0")
    out = subprocess.run([sys.executable, "-c", TIME, str(scene)], env=env, check=True, capture_output=True, text=True)
    return float(out.stdout.strip())


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--counts", default="5,16,32,48,64,96")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        scenes = {"lit_showcase": LIT, "lit_showcase_no_spheres": Path(tmp) / "none.toml"}
        scenes["lit_showcase_no_spheres"].write_text(floor_of_spheres(0), encoding="utf-8")
        for n in (int(c) for c in args.counts.split(",")):
            scenes[f"floor_{n}_spheres"] = Path(tmp) / f"floor_{n}.toml"
            scenes[f"floor_{n}_spheres"].write_text(floor_of_spheres(n), encoding="utf-8")
        best: dict[str, dict[str, float]] = {name: {"own": float("inf"), "embree": float("inf")} for name in scenes}
        for _ in range(args.repeat):
            for name, path in scenes.items():
                for kind in ("embree", "own"):
                    best[name][kind] = min(best[name][kind], cpu_seconds(path, own=kind == "own"))
    result = {
        "benchmark": "still spheres: own test against Embree's, thin lens 360x240, 64 spp, 2 threads",
        "repeat": args.repeat,
        "best_cpu_seconds": best,
        "embree_over_own": {name: b["embree"] / b["own"] for name, b in best.items()},
    }
    print(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
