"""Time to a given error: POV-Ray's focal blur against the native thin lens.

On one scene (default ``reference_scenes/showcase.toml``), one resolution and
one thread count, both renderers are swept over sample counts; each render's
relative RMSE (RMSE / mean of the reference) is taken against a converged
reference — the native thin lens at a high sample count — and the time each
renderer needs to reach ``--target`` is interpolated (log time against log
error between the two bracketing renders). Each renderer is also swept in its
adaptive mode — native ``adaptive=True`` (a first pass finds the noisy
pixels), POV-Ray's adaptive focal blur (``blur_samples 4, MAX`` with a
``variance`` threshold) — and the goal is judged with each at its best. Before trusting that, the script
checks that POV-Ray at a high ``blur_samples`` converges to the same image:
its error at the two highest counts is split into noise (falling as 1/sqrt(N))
and a floor; the floor, less the reference's own noise, is the systematic
difference between the renderers, which must be well below ``--target``.

Times: ``seconds`` is render time only on both sides (native: the render loop,
no BVH build; POV-Ray: its own "Trace Time", no parsing or process start);
``wall_seconds`` is what a user waits (for POV-Ray including process start,
parsing and writing the EXR). The headline ratio uses render times; the wall
ratio is reported beside it, and so is the ratio of CPU time (all threads;
native: this process's, POV-Ray: its own count for the trace), which other
work on a shared machine disturbs least. The machine may be shared: each sweep point is rendered ``--repeat`` times and
the fastest run kept (both renderers give the same image every time).

Prints one JSON object. Not a test. Usage::

    .venv/bin/python bench/bench_povray.py [--scene S] [--threads 2] [--target 0.02]
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import sys
import time
from pathlib import Path


ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from lenscompare.metrics import relative_rmse, ssim  # noqa: E402
from lenscompare.povray import render_povray  # noqa: E402
from lenscompare.render import render  # noqa: E402
from lenscompare.scene import load_scene  # noqa: E402

GOAL_RATIO = 10.0


def spp_list(text: str) -> list[int]:
    return [int(v) for v in text.split(",") if v.strip()]


def time_to_target(points, target, key="seconds"):
    """Interpolated time at which the error first reaches ``target`` (None if never).

    Points are taken in order of effort: sample count for fixed counts, time
    for adaptive sweeps (whose settings are not sample counts)."""
    points = sorted(points, key=lambda p: (p.get("effort", p["spp"]), p["seconds"]))
    for before, after in zip([None, *points[:-1]], points):
        if after["relative_rmse"] <= target:
            if before is None or before["relative_rmse"] <= after["relative_rmse"]:
                return after[key]
            # log-log interpolation between the bracketing renders
            t = (math.log(before["relative_rmse"]) - math.log(target)) / (
                math.log(before["relative_rmse"]) - math.log(after["relative_rmse"]))
            return math.exp(math.log(before[key]) + t * (math.log(after[key]) - math.log(before[key])))
    return None


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scene", default=str(ROOT / "reference_scenes" / "showcase.toml"))
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--target", type=float, default=0.02, help="relative RMSE to reach (0.02 = 2 %%)")
    parser.add_argument("--reference-spp", type=int, default=4096, help="native spp of the converged reference")
    parser.add_argument("--native-spp", type=spp_list, default=spp_list("1,2,4,8,16,32,64,128,256"))
    parser.add_argument("--povray-spp", type=spp_list, default=spp_list("4,8,16,32,64,128,256,512"))
    parser.add_argument("--povray-converged-spp", type=int, default=1024,
                        help="blur_samples of the POV-Ray render checked against the reference")
    parser.add_argument("--repeat", type=int, default=3,
                        help="render each sweep point this often and keep the fastest (the machine may be shared)")
    parser.add_argument("--sampler", default="sobol", help="native sampler for the sweeps (the reference is jittered)")
    parser.add_argument("--adaptive-spp", type=spp_list, default=spp_list("8,12,16,24,32,48,64"),
                        help="mean spp of the native adaptive sweep (empty: none)")
    parser.add_argument("--povray-variances", default="0.0078125,0.0009765625,0.0001220703125,0.0000152587890625,"
                        "0.0000019073486328125", help="POV-Ray adaptive focal blur sweep: variance thresholds")
    parser.add_argument("--povray-adaptive-max", type=int, default=1024,
                        help="POV-Ray adaptive focal blur: most samples a pixel takes (min is 4)")
    parser.add_argument("--save", metavar="DIR", help="also write the reference and high-spp renders as EXR here")
    args = parser.parse_args()

    scene = load_scene(args.scene)
    log = lambda *a: print(*a, file=sys.stderr, flush=True)  # noqa: E731

    log(f"reference: native thin lens, {args.reference_spp} spp")
    reference = render(scene, model="thin", spp=args.reference_spp, threads=args.threads, progress=False)
    ref = reference.pixels

    def entry(image, start, cpu_start):
        return {
            "spp": image.metadata["spp"],
            "seconds": image.metadata["seconds"],
            "wall_seconds": image.metadata.get("wall_seconds", time.perf_counter() - start),
            # POV-Ray: its own CPU time for the trace; native: this process's CPU time (all threads)
            "cpu_seconds": image.metadata.get("cpu_seconds") or (time.process_time() - cpu_start),
            "relative_rmse": relative_rmse(ref, image.pixels),
            "ssim": ssim(ref, image.pixels, data_range=1.0),
        }

    def fastest(run):
        """The fastest of ``--repeat`` runs (both renderers are deterministic: same image each time)."""
        runs = []
        for _ in range(max(args.repeat, 1)):
            start, cpu_start = time.perf_counter(), time.process_time()
            runs.append(entry(run(), start, cpu_start))
        return min(runs, key=lambda r: r["seconds"]) | {
            "wall_seconds": min(r["wall_seconds"] for r in runs),
            "cpu_seconds": min(r["cpu_seconds"] for r in runs), "runs": len(runs)}

    native = []
    for spp in args.native_spp:
        native.append(fastest(lambda: render(scene, model="thin", spp=spp, sampler=args.sampler, threads=args.threads,
                                             progress=False)))
        log(f"native {spp:5d} spp: {native[-1]['seconds']:.3f} s, relative RMSE {native[-1]['relative_rmse']:.4f}")

    native_adaptive = []
    for spp in args.adaptive_spp:
        native_adaptive.append(fastest(lambda: render(scene, model="thin", spp=spp, sampler=args.sampler,
                                                      threads=args.threads, progress=False, adaptive=True)))
        log(f"native adaptive {spp:5d} spp: {native_adaptive[-1]['seconds']:.3f} s, "
            f"relative RMSE {native_adaptive[-1]['relative_rmse']:.4f}")

    povray_adaptive = []
    variances = sorted((float(v) for v in args.povray_variances.split(",") if v.strip()), reverse=True)
    for effort, variance in enumerate(variances):
        povray_adaptive.append(fastest(lambda: render_povray(scene, model="thin", spp=args.povray_adaptive_max,
                                                             threads=args.threads, blur_adaptive=(4, variance)))
                               | {"effort": effort, "variance": variance})
        log(f"POV-Ray adaptive variance {variance:g}: {povray_adaptive[-1]['seconds']:.3f} s, "
            f"relative RMSE {povray_adaptive[-1]['relative_rmse']:.4f}")

    povray = []
    for spp in args.povray_spp:
        povray.append(fastest(lambda: render_povray(scene, model="thin", spp=spp, threads=args.threads)))
        log(f"POV-Ray {spp:5d} spp: {povray[-1]['seconds']:.3f} s, relative RMSE {povray[-1]['relative_rmse']:.4f}")

    # Does POV-Ray converge to the native reference? Compare its high-sample
    # error with a native render of the same sample count (pure noise).
    log(f"convergence check: POV-Ray and native at {args.povray_converged_spp} spp")
    pov_high = render_povray(scene, model="thin", spp=args.povray_converged_spp, threads=args.threads)
    version, command = pov_high.metadata["renderer"], pov_high.metadata["command"]
    native_high = render(scene, model="thin", spp=args.povray_converged_spp, threads=args.threads, progress=False)
    convergence = {
        "spp": args.povray_converged_spp,
        "povray_relative_rmse": relative_rmse(ref, pov_high.pixels),
        "native_relative_rmse": relative_rmse(ref, native_high.pixels),
        "povray_ssim": ssim(ref, pov_high.pixels, data_range=1.0),
        "povray_over_native_mean": float(pov_high.pixels.mean() / ref.mean()),
        "povray_seconds": pov_high.metadata["seconds"],
    }
    # Noise and a systematic difference add in quadrature: fit err² = a / N + floor² through
    # POV-Ray's two highest sample counts (assumes its noise falls as 1/sqrt(N) there). The
    # floor includes the reference's own noise, estimated from the native render at the same
    # count: err² = noise(N)² + noise(reference)², noise ∝ 1/sqrt(spp).
    n_lo = max((p for p in povray if p["spp"] < args.povray_converged_spp), key=lambda p: p["spp"], default=None)
    if n_lo is not None:
        e_lo, e_hi = n_lo["relative_rmse"], convergence["povray_relative_rmse"]
        n1, n2 = n_lo["spp"], args.povray_converged_spp
        a = (e_lo**2 - e_hi**2) / (1.0 / n1 - 1.0 / n2)
        floor2 = max(e_hi**2 - a / n2, 0.0)
        ratio_ref = args.povray_converged_spp / args.reference_spp
        reference_noise2 = convergence["native_relative_rmse"] ** 2 * ratio_ref / (1.0 + ratio_ref)
        convergence["fit_spp"] = [n1, n2]
        convergence["floor_relative_rmse"] = math.sqrt(floor2)
        convergence["reference_noise_relative_rmse"] = math.sqrt(reference_noise2)
        convergence["systematic_relative_rmse_estimate"] = math.sqrt(max(floor2 - reference_noise2, 0.0))
    if args.save:
        from lenscompare.image import write_exr

        folder = Path(args.save)
        folder.mkdir(parents=True, exist_ok=True)
        write_exr(folder / f"native_{args.reference_spp}spp.exr", reference)
        write_exr(folder / f"povray_{args.povray_converged_spp}spp.exr", pov_high)
        write_exr(folder / f"native_{args.povray_converged_spp}spp.exr", native_high)

    t_native = time_to_target(native, args.target)
    t_povray = time_to_target(povray, args.target)
    c_native = time_to_target(native, args.target, key="cpu_seconds")
    c_povray = time_to_target(povray, args.target, key="cpu_seconds")
    w_native = time_to_target(native, args.target, key="wall_seconds")
    w_povray = time_to_target(povray, args.target, key="wall_seconds")
    ratio = t_povray / t_native if t_native and t_povray else None
    # Each renderer at its best: the faster of its fixed-count and adaptive sweeps.
    best = {}
    for who, sweeps in (("native", {"uniform": native, "adaptive": native_adaptive}),
                        ("povray", {"fixed": povray, "adaptive": povray_adaptive})):
        times = {name: time_to_target(points, args.target) for name, points in sweeps.items() if points}
        found = {name: t for name, t in times.items() if t is not None}
        best[who] = {"seconds_by_mode": times, "mode": min(found, key=found.get) if found else None,
                     "seconds": min(found.values()) if found else None}
    best_ratio = (best["povray"]["seconds"] / best["native"]["seconds"]
                  if best["native"]["seconds"] and best["povray"]["seconds"] else None)
    result = {
        "benchmark": "time to reach a relative RMSE: POV-Ray focal blur vs native thin lens",
        "scene": scene.name,
        "resolution": list(scene.camera.resolution),
        "threads": args.threads,
        "target_relative_rmse": args.target,
        "reference": {"renderer": "native thin lens", "spp": args.reference_spp,
                      "seconds": reference.metadata["seconds"], "sampler": reference.metadata["sampler"]},
        "povray_version": version,
        "povray_command": command,
        "povray_converges_to_reference": convergence,
        "native": native,
        "native_adaptive": native_adaptive,
        "povray": povray,
        "povray_adaptive": povray_adaptive,
        "best_to_target": {**best, "ratio_povray_over_native": best_ratio},
        "time_to_target": {
            "native_seconds": t_native,
            "povray_seconds": t_povray,
            "ratio_povray_over_native": ratio,
            "native_wall_seconds": w_native,
            "povray_wall_seconds": w_povray,
            "wall_ratio_povray_over_native": w_povray / w_native if w_native and w_povray else None,
            "native_cpu_seconds": c_native,
            "povray_cpu_seconds": c_povray,
            "cpu_ratio_povray_over_native": c_povray / c_native if c_native and c_povray else None,
        },
        "by_target": [
            {"target_relative_rmse": target,
             **{f"{who}_{key}": time_to_target(points, target, key=key)
                for who, points in (("native", native), ("povray", povray))
                for key in ("seconds", "cpu_seconds", "wall_seconds")}}
            for target in sorted({0.05, 0.02, 0.01, args.target}, reverse=True)
        ],
        "goal_ratio": GOAL_RATIO,
        # The goal is judged with each renderer at its best (adaptive or not).
        "goal_met": bool(best_ratio is not None and best_ratio >= GOAL_RATIO),
        "machine": platform.machine(),
        "python": platform.python_version(),
    }
    print(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
