"""Still quads: the render's own test (native quad_lanes.cpp) against Embree's, in CPU seconds of the render loop.

Each scene renders twice per round, once with the own test (its limit lifted
to see past it) and once with ``LENSCOMPARE_MAX_OWN_QUADS=0`` (Embree, with
its robust traversal, intersects the quads); rounds alternate and each keeps
its best. The cost is this process's CPU time of a 64-spp render less that of
a 1-spp render (the set-up), 1 thread, thin lens, 240 x 160. Scenes:
lit_showcase and showcase (a box and a rectangle: 7 quads, 5 spheres) and
bench/scenes/peers_lit.toml cut to its first 1 to 4 boxes (7, 13, 19, 25
quads with the wall; 4 spheres, 3 lights): where one test per quad per ray
meets Embree's BVH, which sets the render's limit (quad_lanes.h).
Prints one JSON object. Not a test. Usage::

    flock /tmp/bench.lock .venv/bin/python bench/bench_quads.py [--repeat 3]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from lenscompare.render import render  # noqa: E402
from lenscompare.scene import Box, load_scene  # noqa: E402


def scenes() -> dict:
    out = {name: load_scene(ROOT / "reference_scenes" / f"{name}.toml") for name in ("lit_showcase", "showcase")}
    peers = load_scene(ROOT / "bench" / "scenes" / "peers_lit.toml")
    boxes = [o for o in peers.objects if isinstance(o, Box)]
    others = [o for o in peers.objects if not isinstance(o, Box)]
    for n in range(1, len(boxes) + 1):
        out[f"peers_lit_{n}_boxes_{6 * n + 1}_quads"] = dataclasses.replace(peers, objects=tuple(others + boxes[:n]))
    return {name: scene.with_camera(resolution=(240, 160)) for name, scene in out.items()}


def loop_seconds(scene, *, own: bool) -> float:
    """CPU seconds of the 64-spp render loop (a 1-spp render subtracted)."""
    os.environ["LENSCOMPARE_MAX_OWN_QUADS"] = "1000000" if own else "0"  # read when the native scene is built
    try:
        seconds = []
        for spp in (1, 64):
            start = time.process_time()
            render(scene, model="thin", spp=spp, threads=1, progress=False)
            seconds.append(time.process_time() - start)
        return seconds[1] - seconds[0]
    finally:
        os.environ.pop("LENSCOMPARE_MAX_OWN_QUADS")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    results = {}
    for name, scene in scenes().items():
        best = {"own": float("inf"), "embree": float("inf")}
        for _ in range(args.repeat):
            for key in best:
                best[key] = min(best[key], loop_seconds(scene, own=key == "own"))
        results[name] = {"own_seconds": best["own"], "embree_seconds": best["embree"],
                         "embree_over_own": best["embree"] / best["own"]}
        print(name, json.dumps(results[name]), file=sys.stderr, flush=True)
    print(json.dumps({"benchmark": "own quad test against Embree's, CPU seconds of the render loop, 1 thread",
                      "repeat": args.repeat, "scenes": results}, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
