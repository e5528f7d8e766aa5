"""Whether a native render straight after a Mitsuba 3 render is slower than
one straight after another native render (why bench_peers.py runs its rounds
forward and backward in turn).

In each of ``--repeat`` rounds: a Mitsuba ``llvm_ad_rgb`` pinhole render of
``lit_showcase``, then the native thin lens twice and the pinhole; then
Mitsuba again, the pinhole twice and the thin lens; then Mitsuba twice (the
first after a native render). Each position keeps its best samples/s. Usage::

    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 \\
        flock /tmp/bench.lock .venv/bin/python bench/bench_peers_order.py [--repeat 6]

Prints one JSON object. Not a test.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile

from bench_peers import SCENES, MitsubaRender, load_mitsuba, native_timer

from lenscompare.scene import load_scene


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=6)
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--threads", type=int, default=2)
    args = parser.parse_args()
    scene = load_scene(SCENES["lit_showcase"]).with_camera(resolution=(240, 160))
    mi = load_mitsuba("llvm_ad_rgb")
    import drjit as dr

    dr.set_thread_count(args.threads)
    samples = 240 * 160 * args.spp
    with tempfile.TemporaryDirectory(prefix="bench-order-") as folder:
        mitsuba = MitsubaRender(mi, "llvm_ad_rgb", scene, "pinhole", args.spp, folder).seconds
        thin = native_timer(scene, "thin", args.spp, args.threads)
        pinhole = native_timer(scene, "pinhole", args.spp, args.threads)
        best = {}

        def keep(name, seconds):
            best[name] = max(best.get(name, 0.0), samples / seconds / 1e6)

        for _ in range(args.repeat):
            mitsuba()
            keep("thin_after_mitsuba", thin())
            keep("thin_after_thin", thin())
            keep("pinhole_after_thin", pinhole())
            mitsuba()
            keep("pinhole_after_mitsuba", pinhole())
            keep("pinhole_after_pinhole", pinhole())
            keep("thin_after_pinhole", thin())
            keep("mitsuba_after_native", mitsuba())
            keep("mitsuba_after_mitsuba", mitsuba())
    result = {
        "benchmark": "samples/s straight after the other renderer's render and after its own",
        "scene": "lit_showcase", "spp": args.spp, "threads": args.threads, "repeat": args.repeat,
        "m_samples_per_second": {k: round(v, 3) for k, v in best.items()},
        "thin_after_mitsuba_over_after_native": best["thin_after_mitsuba"] / max(best["thin_after_thin"],
                                                                                  best["thin_after_pinhole"]),
        "pinhole_after_mitsuba_over_after_native": best["pinhole_after_mitsuba"] / max(
            best["pinhole_after_pinhole"], best["pinhole_after_thin"]),
        "mitsuba_after_native_over_after_mitsuba": best["mitsuba_after_native"] / best["mitsuba_after_mitsuba"],
    }
    json.dump(result, sys.stdout, indent=2)
    print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
