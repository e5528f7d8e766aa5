"""Whether a native render straight after a Mitsuba 3 render is slower than
one straight after another native render, and whether letting the process's
other threads go idle first (idle_threads.py, as bench_peers.py does) removes it.

In each of ``--repeat`` rounds, for the native thin lens and the pinhole: a
Mitsuba ``llvm_ad_rgb`` render of the scene, then the native render twice;
the same with ``wait_for_idle_threads()`` between the Mitsuba render and the
first native one; and a native render followed by two of Mitsuba's. Each
ratio is the first render's time over the second's, median over the rounds
(1: no effect). Usage::

    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 \\
        flock /tmp/bench.lock .venv/bin/python bench/bench_peers_order.py [--repeat 12] [--scene peers_lit]

Prints one JSON object. Not a test.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile

from bench_peers import SCENES, MitsubaRender, load_mitsuba, native_timer
from idle_threads import wait_for_idle_threads

from lenscompare.scene import load_scene


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=12)
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--scene", default="peers_lit", choices=sorted(SCENES))
    args = parser.parse_args()
    scene = load_scene(SCENES[args.scene]).with_camera(resolution=(240, 160))
    mi = load_mitsuba("llvm_ad_rgb")
    import drjit as dr

    dr.set_thread_count(args.threads)
    ratios = {}  # each round's first render time over its second's

    def pair(name, first, second):
        ratios.setdefault(name, []).append(first() / second())

    with tempfile.TemporaryDirectory(prefix="bench-order-") as folder:
        mitsuba = {model: MitsubaRender(mi, "llvm_ad_rgb", scene, model, args.spp, folder).seconds
                   for model in ("thin", "pinhole")}
        native = {model: native_timer(scene, model, args.spp, args.threads) for model in ("thin", "pinhole")}
        waited = []
        for _ in range(args.repeat):
            for model in ("thin", "pinhole"):
                mitsuba[model]()
                pair(f"{model}_after_mitsuba_over_after_{model}", native[model], native[model])
                mitsuba[model]()
                waited.append(wait_for_idle_threads())
                pair(f"{model}_after_mitsuba_idle_over_after_{model}", native[model], native[model])
                native[model]()
                pair(f"mitsuba_{model}_after_native_over_after_mitsuba", mitsuba[model], mitsuba[model])
    result = {
        "benchmark": "render time straight after the other renderer's render over after its own (median of rounds)",
        "scene": args.scene, "spp": args.spp, "threads": args.threads, "repeat": args.repeat,
        "time_ratios": {k: round(statistics.median(v), 4) for k, v in ratios.items()},
        "time_ratios_by_round": {k: [round(x, 4) for x in v] for k, v in ratios.items()},
        "idle_wait_ms_median": round(statistics.median(waited) * 1e3, 1),
    }
    json.dump(result, sys.stdout, indent=2)
    print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
