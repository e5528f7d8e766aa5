"""The native tracer against its peers: Mitsuba 3 (scalar and LLVM) and POV-Ray, same scenes, one run.

For each scene, every renderer renders the same picture at the same
resolution, spp and thread count; the renders alternate (one of each per
round, ``--repeat`` rounds) and each keeps its best, so a slow spell of a
shared machine costs all alike. Before each timed render the process's
other threads are let go idle (idle_threads.py): Dr.Jit's workers spin for
about 20 ms after a Mitsuba render returns, and a native render started in
that window shared a core with them (1.08-1.20x its time, session 35;
bench_peers_order.py). The rounds still run forward and backward in turn,
so that no renderer always follows the same one. Times are render time only:

- native: the render loop (no scene build), ``Image.metadata["seconds"]``;
- Mitsuba 3: ``mi.render`` on a scene loaded once, evaluated to an array;
  one render per variant and scene is made first and not counted, so the
  LLVM variant's JIT compilation (and the kernel cache's first look-up) is
  excluded;
- POV-Ray: its own "Trace Time" (no parsing, no process start).

Models: native ``thin``, ``pinhole`` and ``lens`` (Double Gauss 50 mm at
full aperture, as bench_lens.py), Mitsuba ``thin`` (``thinlens``) and
``pinhole`` (``perspective``), POV-Ray ``thin`` (focal blur,
``blur_samples spp``). Scenes: ``lit_showcase`` (the showcase with
inverse-square lights: Mitsuba has no point light without falloff, and the
native cost per sample is the same) and ``bench/scenes/peers_lit.toml``.

Mitsuba's ``direct`` integrator as exported here picks one light per sample
where the native tracer sums every light (one shadow ray per light per
diffuse hit), so per sample the native tracer does more work. And Mitsuba
builds its Embree scene without RTC_SCENE_FLAG_ROBUST (perf names its
triangle kernel ``TriangleMIntersectorKMoeller``), where the native tracer
keeps robust traversal so that no ray slips between primitives sharing an
edge. Two more rows measure what each costs, with the work matched:

- ``native_thin_not_robust``: ``LENSCOMPARE_EMBREE_ROBUST=0`` for that render's scene;
- scene ``<name>_one_light`` (``--one-light``): the scene with its first light
  only, so that both renderers trace one shadow ray per diffuse hit.

The samplers differ too: the scenes draw ``jittered`` samples (one per
stratum of the film and of the lens, the lens strata shuffled), Mitsuba's
export ``independent`` ones. Mitsuba's ``stratified`` sampler is the same
construction as ``jittered``, and the native ``random`` sampler is
``independent``'s. So the LLVM variant is timed with ``stratified`` as well
(``mitsuba_llvm_ad_rgb_stratified_<model>``, when spp is a square) and the
native tracer with ``random`` (``native_<model>_random``, full scenes), and
two ratios compare like samplers: ``native_<model>_over_mitsuba_llvm_ad_rgb_stratified``
and ``native_<model>_random_over_mitsuba_llvm_ad_rgb``.

With ``--empty``, each scene is timed again with its objects removed (camera,
lights and background kept; thin lens and pinhole only): every ray misses,
so what is left per sample is the work around the rays (sampling, camera
rays, batching, shading set-up, accumulation). ``decomposition`` then splits
each renderer's nanoseconds per sample and thread into that pipeline cost
(the empty scene's) and the scene's own (intersection and shading: the
full scene's less the empty one's).

With ``--time-to-rmse``, ``bench_povray.py`` also runs (uniform sampling
only: POV-Ray fixed ``blur_samples`` against the native thin lens's sobol
sweep) and its ``time_to_target`` goes into the JSON.

Usage::

    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 \\
        flock /tmp/bench.lock .venv/bin/python bench/bench_peers.py [--repeat 5] [--one-light] [--time-to-rmse]

(``make bench`` sets the variable.) Prints one JSON object. Not a test.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from lenscompare.errors import ExternalError  # noqa: E402
from lenscompare.mitsuba.export import scene_to_mitsuba  # noqa: E402
from lenscompare.mitsuba.runner import load_mitsuba, write_mitsuba  # noqa: E402
from lenscompare.povray import render_povray  # noqa: E402
from lenscompare.render import render  # noqa: E402
from lenscompare.scene import load_scene  # noqa: E402
from idle_threads import wait_for_idle_threads  # noqa: E402
from machine import describe as describe_machine  # noqa: E402

SCENES = {
    "lit_showcase": ROOT / "reference_scenes" / "lit_showcase.toml",
    "peers_lit": ROOT / "bench" / "scenes" / "peers_lit.toml",
}
LENS = "dgauss.50mm"
VARIANTS = ("scalar_rgb", "llvm_ad_rgb")
GOAL_OVER_LLVM = 1.2
GOAL_LENS_OVER_PINHOLE = 0.85
GOAL_POVRAY_TIME_RATIO = 10.0


def log(*parts):
    print(*parts, file=sys.stderr, flush=True)


class MitsubaRender:
    """One scene loaded once in one Mitsuba variant; ``seconds()`` times one render."""

    def __init__(self, mi, variant, scene, model, spp, folder, sampler="independent"):
        self.mi, self.variant = mi, variant
        mi.set_variant(variant)
        path = Path(folder) / f"{scene.name}_{model}_{variant}_{sampler}.xml"
        write_mitsuba(scene_to_mitsuba(scene, model=model, spp=spp, seed=0, sampler=sampler), path)
        self.loaded = mi.load_file(str(path))
        self.seconds()  # JIT warm-up, not counted

    def seconds(self):
        self.mi.set_variant(self.variant)
        start = time.perf_counter()
        np.asarray(self.mi.render(self.loaded, seed=0))  # the array forces evaluation
        return time.perf_counter() - start


def native_timer(scene, model, spp, threads, *, robust=True, lens_mirrors=False, lens_rays=None):
    def run():
        # Read when the native scene is built: each render builds its own.
        os.environ["LENSCOMPARE_EMBREE_ROBUST"] = "1" if robust else "0"
        try:
            return render(scene, model=model, spp=spp, threads=threads, progress=False,
                          lens_mirrors=lens_mirrors, lens_rays=lens_rays).metadata["seconds"]
        finally:
            os.environ.pop("LENSCOMPARE_EMBREE_ROBUST")
    return run


def povray_timer(scene, spp, threads):
    def run():
        return render_povray(scene, model="thin", spp=spp, threads=threads).metadata["seconds"]
    return run


def time_to_rmse(threads):
    """bench_povray.py with uniform sampling only; its time_to_target block."""
    command = [sys.executable, str(ROOT / "bench" / "bench_povray.py"), "--threads", str(threads),
               "--adaptive-spp", "", "--povray-variances", "", "--repeat", "2"]
    log("time to 2 % RMSE:", " ".join(command))
    out = subprocess.run(command, check=True, capture_output=True, text=True).stdout
    result = json.loads(out)
    return {"command": " ".join(command[1:]), **result["time_to_target"],
            "povray_converges_to_reference": result["povray_converges_to_reference"]}


def decomposition(scenes, threads):
    """Nanoseconds per sample and thread, each renderer's: the pipeline's (the
    scene without objects) and the scene's own (the full scene's less that)."""
    out = {}
    for name, entry in scenes.items():
        empty = scenes.get(f"{name}_empty")
        if empty is None:
            continue
        out[name] = {}
        for key, full_sps in entry["samples_per_second"].items():
            if key not in empty["samples_per_second"]:
                continue
            full_ns = threads / full_sps * 1e9
            pipeline_ns = threads / empty["samples_per_second"][key] * 1e9
            out[name][key] = {"total_ns": full_ns, "pipeline_ns": pipeline_ns, "scene_ns": full_ns - pipeline_ns}
    return out


def spread(seconds_by_key: dict, samples: int) -> dict:
    """Each renderer's median samples/s over the rounds and its fastest round over its slowest (as
    bench_native's and bench_lens's), the llvm ratios of the medians, and the median over the
    rounds of each round's own ratio (the two renders of a round a second or so apart, so that a
    slow spell of the machine lasting longer than that costs both): how far the best-of ratios
    could move on this machine."""
    median = {key: samples / statistics.median(times) for key, times in seconds_by_key.items()}
    out = {"median_samples_per_second": median,
           "fastest_over_slowest_round": {key: max(t) / min(t) for key, t in seconds_by_key.items()}}
    models = [m for m in ("thin", "pinhole") if f"native_{m}" in median and f"mitsuba_llvm_ad_rgb_{m}" in median]
    out["median_ratios"] = {f"native_{m}_over_mitsuba_llvm_ad_rgb": median[f"native_{m}"] /
                            median[f"mitsuba_llvm_ad_rgb_{m}"] for m in models}
    out["median_round_ratios"] = {
        f"native_{m}_over_mitsuba_llvm_ad_rgb": statistics.median(
            t_mitsuba / t_native for t_native, t_mitsuba in zip(seconds_by_key[f"native_{m}"],
                                                                seconds_by_key[f"mitsuba_llvm_ad_rgb_{m}"]))
        for m in models}
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--resolution", type=int, nargs=2, default=(240, 160), metavar=("W", "H"))
    parser.add_argument("--repeat", type=int, default=5, help="alternating rounds; each renderer keeps its best")
    parser.add_argument("--scenes", default=",".join(SCENES), help="comma-separated names from " + ", ".join(SCENES))
    parser.add_argument("--no-mitsuba", action="store_true")
    parser.add_argument("--no-povray", action="store_true")
    parser.add_argument("--one-light", action="store_true",
                        help="also each scene with its first light only (one shadow ray per hit, as Mitsuba)")
    parser.add_argument("--empty", action="store_true",
                        help="also each scene without its objects: the pipeline's cost per sample apart from the scene's")
    parser.add_argument("--time-to-rmse", action="store_true", help="also run bench_povray.py (uniform sampling)")
    args = parser.parse_args()

    mi = None
    variants = {}
    if not args.no_mitsuba:
        for variant in VARIANTS:
            try:
                mi = load_mitsuba(variant)
                variants[variant] = None
            except ExternalError as error:
                variants[variant] = str(error)
                log(f"Mitsuba {variant} skipped: {error}")
        if mi is not None:
            import drjit as dr

            dr.set_thread_count(args.threads)

    results = {
        "benchmark": "native against Mitsuba 3 and POV-Ray, render time only",
        "spp": args.spp,
        "threads": args.threads,
        "resolution": list(args.resolution),
        "repeat": args.repeat,
        "lens": LENS,
        "mitsuba_version": getattr(mi, "__version__", None),
        "mitsuba_skipped": {v: e for v, e in variants.items() if e},
        "machine": describe_machine(),
        "cpu_count": os.cpu_count(),
        "scenes": {},
    }
    samples = args.resolution[0] * args.resolution[1] * args.spp
    with tempfile.TemporaryDirectory(prefix="bench-peers-") as folder:
        runs = [(name, load_scene(SCENES[name])) for name in args.scenes.split(",")]
        full_runs = list(runs)
        if args.one_light:
            runs += [(f"{name}_one_light", dataclasses.replace(scene, lights=scene.lights[:1]))
                     for name, scene in full_runs]
        if args.empty:
            runs += [(f"{name}_empty", dataclasses.replace(scene, objects=())) for name, scene in full_runs]
        for name, scene in runs:
            empty = name.endswith("_empty")
            scene = scene.with_camera(resolution=tuple(args.resolution))
            lens_scene = scene.with_camera(lens=LENS, f_number=None)
            timers = {
                "native_thin": native_timer(scene, "thin", args.spp, args.threads),
                "native_pinhole": native_timer(scene, "pinhole", args.spp, args.threads),
            }
            if not empty:
                for model in ("thin", "pinhole"):
                    timers[f"native_{model}_random"] = native_timer(scene.with_render(sampler="random"), model,
                                                                    args.spp, args.threads)
                timers["native_thin_not_robust"] = native_timer(scene, "thin", args.spp, args.threads, robust=False)
                timers["native_lens"] = native_timer(lens_scene, "lens", args.spp, args.threads)
                timers["native_lens_mirrored"] = native_timer(lens_scene, "lens", args.spp, args.threads,
                                                              lens_mirrors=True)
                timers["native_lens_table"] = native_timer(lens_scene, "lens", args.spp, args.threads,
                                                           lens_rays="table")
                # Both: what --model auto renders for a lens-system plan.
                timers["native_lens_table_mirrored"] = native_timer(lens_scene, "lens", args.spp, args.threads,
                                                                    lens_rays="table", lens_mirrors=True)
            for variant, error in variants.items():
                if error is None:
                    for model in ("thin", "pinhole"):
                        log(f"{name}: loading Mitsuba {variant} {model} (and a warm-up render)")
                        timers[f"mitsuba_{variant}_{model}"] = MitsubaRender(mi, variant, scene, model, args.spp,
                                                                             folder).seconds
                        if variant == "llvm_ad_rgb" and math.isqrt(args.spp) ** 2 == args.spp:
                            timers[f"mitsuba_{variant}_stratified_{model}"] = MitsubaRender(
                                mi, variant, scene, model, args.spp, folder, sampler="stratified").seconds
            if not args.no_povray and not empty:
                timers["povray_thin"] = povray_timer(scene, args.spp, args.threads)
            best = {key: float("inf") for key in timers}
            every = {key: [] for key in timers}  # each round's seconds: the spread of a noisy machine
            for round_ in range(args.repeat):
                # Serpentine: forward, then backward (see the top).
                order = list(timers) if round_ % 2 == 0 else list(reversed(timers))
                for key in order:
                    wait_for_idle_threads()  # no renderer pays for the spin of the one before it
                    every[key].append(timers[key]())
                    best[key] = min(best[key], every[key][-1])
                log(f"{name} round {round_ + 1}: " + ", ".join(f"{k} {samples / v / 1e6:.2f}" for k, v in best.items())
                    + " M samples/s (best so far)")
            sps = {key: samples / seconds for key, seconds in best.items()}
            ratios = {}
            for model in ("thin", "pinhole"):
                for variant in VARIANTS:
                    if f"mitsuba_{variant}_{model}" in sps:
                        ratios[f"native_{model}_over_mitsuba_{variant}"] = (
                            sps[f"native_{model}"] / sps[f"mitsuba_{variant}_{model}"])
                if f"mitsuba_llvm_ad_rgb_{model}" in sps and f"native_{model}_random" in sps:
                    ratios[f"native_{model}_random_over_mitsuba_llvm_ad_rgb"] = (
                        sps[f"native_{model}_random"] / sps[f"mitsuba_llvm_ad_rgb_{model}"])
                if f"mitsuba_llvm_ad_rgb_stratified_{model}" in sps:
                    ratios[f"native_{model}_over_mitsuba_llvm_ad_rgb_stratified"] = (
                        sps[f"native_{model}"] / sps[f"mitsuba_llvm_ad_rgb_stratified_{model}"])
            if "mitsuba_llvm_ad_rgb_thin" in sps and "native_thin_not_robust" in sps:
                ratios["native_thin_not_robust_over_mitsuba_llvm_ad_rgb"] = (
                    sps["native_thin_not_robust"] / sps["mitsuba_llvm_ad_rgb_thin"])
            if not empty:
                ratios["native_thin_not_robust_over_native_thin"] = sps["native_thin_not_robust"] / sps["native_thin"]
                ratios["native_lens_over_native_pinhole"] = sps["native_lens"] / sps["native_pinhole"]
                # render(lens_mirrors=True): a quarter of the samples traced, the rest reflected
                ratios["native_lens_mirrored_over_native_pinhole"] = sps["native_lens_mirrored"] / sps["native_pinhole"]
                # [render] lens_rays = "table": the rays interpolated from a table traced once per camera
                ratios["native_lens_table_over_native_pinhole"] = sps["native_lens_table"] / sps["native_pinhole"]
                ratios["native_lens_table_mirrored_over_native_pinhole"] = (
                    sps["native_lens_table_mirrored"] / sps["native_pinhole"])
            ratios["native_thin_over_native_pinhole"] = sps["native_thin"] / sps["native_pinhole"]
            if "povray_thin" in sps:
                ratios["native_thin_over_povray_thin"] = sps["native_thin"] / sps["povray_thin"]
            base = name.removesuffix("_one_light").removesuffix("_empty")
            note = " (first light only)" if name.endswith("_one_light") else " (no objects)" if empty else ""
            results["scenes"][name] = {
                "source": str(SCENES[base].relative_to(ROOT)) + note,
                "best_seconds": best,
                "samples_per_second": sps,
                "ratios": ratios,
                "spread": spread(every, samples),
            }

    if args.empty:
        results["decomposition"] = decomposition(results["scenes"], args.threads)
    if args.time_to_rmse:
        results["povray_time_to_2_percent_uniform"] = time_to_rmse(args.threads)

    goals = {}
    for name, entry in results["scenes"].items():
        if name.endswith(("_one_light", "_empty")):
            continue  # matched work or no scene: not the goal's scenes
        for model in ("thin", "pinhole"):
            ratio = entry["ratios"].get(f"native_{model}_over_mitsuba_llvm_ad_rgb")
            if ratio is not None:
                goals[f"{name}_{model}_over_llvm_ge_{GOAL_OVER_LLVM}"] = ratio >= GOAL_OVER_LLVM
        goals[f"{name}_lens_over_pinhole_ge_{GOAL_LENS_OVER_PINHOLE}"] = (
            entry["ratios"]["native_lens_over_native_pinhole"] >= GOAL_LENS_OVER_PINHOLE)
        # The lens system as --model auto renders it: rays from the table, mirrored.
        goals[f"{name}_lens_table_mirrored_over_pinhole_ge_{GOAL_LENS_OVER_PINHOLE}"] = (
            entry["ratios"]["native_lens_table_mirrored_over_native_pinhole"] >= GOAL_LENS_OVER_PINHOLE)
    rmse = results.get("povray_time_to_2_percent_uniform")
    if rmse and rmse.get("ratio_povray_over_native"):
        goals[f"povray_time_ratio_ge_{GOAL_POVRAY_TIME_RATIO}"] = rmse["ratio_povray_over_native"] >= \
            GOAL_POVRAY_TIME_RATIO
    results["goals_met"] = goals
    print(json.dumps(results, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
