"""Native against Mitsuba 3 at equal error: time to reach a relative RMSE.

``bench_peers.py`` compares samples per second, but a native sample and a
Mitsuba sample do different work: the native tracer sends a shadow ray to
every light and stratifies its samples (jittered or sobol); the exported
Mitsuba ``direct`` integrator picks one light per sample with the
``independent`` sampler. What a user waits for is an image of a given
noise, so this script sweeps sample counts for both on the same scene,
measures each image's relative RMSE against one converged native render
(Mitsuba's images converge to it: ``tests/test_mitsuba.py``), and
interpolates the render time at which each reaches ``--target``
(log-log, as ``bench_povray.py``). Render time only, Mitsuba's JIT
warm-up excluded (one untimed render per sample count), best of
``--repeat``. The export writes Mitsuba's ``independent`` sampler unless
asked; the sweep asks for its stratified samplers too (``--mitsuba-samplers``)
and compares native with the one that gets there first.

Prints one JSON object; a ratio (Mitsuba's time over native's) > 1 means
native reaches the target sooner.

Run::

    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 \\
        flock /tmp/bench.lock .venv/bin/python bench/bench_mitsuba_noise.py [--variant llvm_ad_rgb]
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

BENCH = Path(__file__).resolve().parent
ROOT = BENCH.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(BENCH))

from bench_povray import spp_list, time_to_target  # noqa: E402
from idle_threads import wait_for_idle_threads  # noqa: E402

from lenscompare.metrics import relative_rmse  # noqa: E402
from lenscompare.mitsuba.export import scene_to_mitsuba  # noqa: E402
from lenscompare.mitsuba.runner import load_mitsuba, write_mitsuba  # noqa: E402
from lenscompare.render import render  # noqa: E402
from lenscompare.scene import load_scene  # noqa: E402


def log(*parts):
    print(*parts, file=sys.stderr, flush=True)


def mitsuba_sweep(mi, scene, model, counts, repeat, reference, folder, sampler):
    """Per sample count: the fastest of ``repeat`` timed renders and its error."""
    points = []
    for spp in counts:
        path = Path(folder) / f"{scene.name}_{model}_{spp}_{sampler}.xml"
        # The export's default sampler is Mitsuba's plain independent one; a stratified one is its best case.
        write_mitsuba(scene_to_mitsuba(scene, model=model, spp=spp, seed=0, sampler=sampler), path)
        loaded = mi.load_file(str(path))
        used = int(loaded.sensors()[0].sampler().sample_count())  # ldsampler and multijitter round the count
        np.asarray(mi.render(loaded, seed=0))  # JIT warm-up, not counted
        best, pixels = float("inf"), None
        for _ in range(repeat):
            wait_for_idle_threads()
            start = time.perf_counter()
            pixels = np.array(mi.render(loaded, seed=0), dtype=np.float32)  # the array forces evaluation
            best = min(best, time.perf_counter() - start)
        points.append({"spp": spp, "spp_used": used, "seconds": best, "relative_rmse": relative_rmse(reference, pixels)})
        log(f"mitsuba {spp:5d} spp ({used} used): {best:.3f} s, relative RMSE {points[-1]['relative_rmse']:.4f}")
    return points


def native_sweep(scene, model, counts, repeat, threads, sampler, reference):
    points = []
    for spp in counts:
        runs = []
        for _ in range(repeat):
            wait_for_idle_threads()  # Dr.Jit's workers spin for a while after the Mitsuba sweep
            runs.append(render(scene, model=model, spp=spp, sampler=sampler, threads=threads, progress=False))
        points.append({"spp": spp, "seconds": min(r.metadata["seconds"] for r in runs),
                       "relative_rmse": relative_rmse(reference, runs[0].pixels)})
        log(f"native  {spp:5d} spp: {points[-1]['seconds']:.3f} s, relative RMSE {points[-1]['relative_rmse']:.4f}")
    return points


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scene", default=str(ROOT / "reference_scenes" / "lit_showcase.toml"))
    parser.add_argument("--model", default="thin", choices=("thin", "pinhole"))
    parser.add_argument("--variant", default="llvm_ad_rgb", choices=("scalar_rgb", "llvm_ad_rgb"))
    parser.add_argument("--resolution", type=int, nargs=2, default=(240, 160), metavar=("W", "H"))
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--target", type=float, default=0.02, help="relative RMSE to reach (0.02 = 2 %%)")
    parser.add_argument("--reference-spp", type=int, default=4096, help="native spp of the converged reference")
    parser.add_argument("--native-spp", type=spp_list, default=spp_list("4,8,16,32,64,128"))
    parser.add_argument("--mitsuba-spp", type=spp_list, default=spp_list("16,32,64,128,256,512,1024"))
    parser.add_argument("--mitsuba-samplers", default="independent,ldsampler,multijitter,orthogonal",
                        help="Mitsuba sampler plugins to sweep, comma-separated (independent is the export's "
                        "default; stratified, which takes square counts only, multijitter, orthogonal, ldsampler)")
    parser.add_argument("--sampler", default="sobol", help="native sampler of the sweep")
    parser.add_argument("--repeat", type=int, default=3, help="timed renders per point; the fastest counts")
    args = parser.parse_args()

    scene = load_scene(args.scene).with_camera(resolution=tuple(args.resolution))
    mi = load_mitsuba(args.variant)
    mi.set_log_level(mi.LogLevel.Error)  # its warnings (rounded sample counts) go to stdout, the JSON's stream
    log(f"reference: native {args.model}, {args.reference_spp} spp")
    reference = render(scene, model=args.model, spp=args.reference_spp, threads=args.threads,
                       progress=False).pixels
    native = native_sweep(scene, args.model, args.native_spp, args.repeat, args.threads, args.sampler, reference)
    samplers = [name for name in args.mitsuba_samplers.split(",") if name.strip()]
    mitsuba = {}
    with tempfile.TemporaryDirectory(prefix="bench-mitsuba-noise-") as folder:
        for sampler in samplers:
            log(f"Mitsuba {args.variant}, sampler {sampler}")
            mitsuba[sampler] = mitsuba_sweep(mi, scene, args.model, args.mitsuba_spp, args.repeat, reference, folder,
                                             sampler)
    t_native = time_to_target(native, args.target)
    t_mitsuba = {sampler: time_to_target(points, args.target) for sampler, points in mitsuba.items()}
    reached = {sampler: t for sampler, t in t_mitsuba.items() if t}
    best = min(reached, key=reached.get) if reached else None
    results = {
        "benchmark": "time to a relative RMSE, native against Mitsuba 3, render time only",
        "scene": scene.name, "model": args.model, "variant": args.variant,
        "resolution": list(args.resolution), "threads": args.threads, "target": args.target,
        "native_sampler": args.sampler, "reference_spp": args.reference_spp,
        "native": native, "mitsuba": mitsuba,
        "native_seconds_to_target": t_native, "mitsuba_seconds_to_target": t_mitsuba,
        "ratio_mitsuba_over_native": {sampler: (t / t_native if t and t_native else None)
                                      for sampler, t in t_mitsuba.items()},
        "best_mitsuba_sampler": best,
        "ratio_best_mitsuba_over_native": (reached[best] / t_native) if best and t_native else None,
    }
    print(json.dumps(results, indent=2), flush=True)  # before Mitsuba's teardown, which may crash at exit
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
