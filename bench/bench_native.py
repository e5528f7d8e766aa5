"""Native tracer throughput on showcase.toml: pinhole and thin lens against raw Embree.

Prints one JSON object. The raw figure is Embree's single-ray primary
throughput (rtcIntersect1 on pinhole rays, no shading, no sampler) on the same
geometry, measured in the same run; the goal is thin-lens samples/s >= 70 %
of it. Two figures per model, because the scene's shading is not camera work:
``*_primary_only`` renders the same scene with its lights removed (camera
rays, sampler, lens mapping and emission/background lookups: the camera path
that raw is the ceiling of), and the full figure adds Lambert shading with one
shadow ray per light per diffuse hit (two lights here).

The four renders alternate, ``--repeats`` rounds, each keeping its best; ``spread`` gives
each one's median round and its fastest over its slowest.

Usage: python bench/bench_native.py [--spp N] [--threads T] [--repeats R]
"""

from __future__ import annotations

import argparse
import json
import os
import dataclasses
import statistics
from pathlib import Path

from lenscompare._native import diagnostics
from lenscompare.cameras import camera_for
from lenscompare.native_scene import build_native_scene
from lenscompare.render import render
from lenscompare.scene import load_scene
from machine import describe as describe_machine

SCENE = Path(__file__).resolve().parent.parent / "reference_scenes" / "showcase.toml"


def alternating_samples_per_second(variants: dict, spp, threads, repeats) -> dict:
    """Each (scene, model) of ``variants`` rendered once per round, ``repeats`` rounds: its
    samples/s in every round, so that a slow spell of the machine lands on all of them alike."""
    runs = {label: [] for label in variants}
    for _ in range(repeats):
        for label, (scene, model) in variants.items():
            runs[label].append(render(scene, model=model, spp=spp, threads=threads,
                                      progress=False).metadata["samples_per_second"])
    return runs


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--threads", type=int, default=os.cpu_count())
    parser.add_argument("--repeats", type=int, default=3, help="alternating rounds; each path keeps its best")
    args = parser.parse_args()

    scene = load_scene(SCENE)
    raw_rays_per_second = 0.0
    camera = camera_for(scene, "pinhole").native()
    native_scene = build_native_scene(scene)
    for _ in range(args.repeats):
        seconds, rays, _hits = diagnostics.raw_primary_throughput(native_scene, camera, args.spp, args.threads)
        raw_rays_per_second = max(raw_rays_per_second, rays / seconds)

    results = {
        "benchmark": "native_throughput",
        "scene": scene.name,
        "resolution": list(scene.camera.resolution),
        "spp": args.spp,
        "threads": args.threads,
        "machine": describe_machine(),
        "cpu_count": os.cpu_count(),
        "raw_embree_primary_rays_per_second": raw_rays_per_second,
    }
    unlit = dataclasses.replace(scene, lights=())
    variants = {label: (variant, model) for model in ("pinhole", "thin")
                for label, variant in ((f"{model}_primary_only", unlit), (model, scene))}
    runs = alternating_samples_per_second(variants, args.spp, args.threads, args.repeats)
    for label, values in runs.items():
        results[f"{label}_samples_per_second"] = max(values)
        results[f"{label}_fraction_of_raw"] = max(values) / raw_rays_per_second
    # How steady the machine was: each path's median round and its fastest over its slowest.
    results["spread"] = {label: {"median_samples_per_second": statistics.median(values),
                                 "fastest_over_slowest_round": max(values) / min(values)}
                         for label, values in runs.items()}
    results["goal_thin_fraction_of_raw"] = 0.7
    results["goal_met_primary_only"] = results["thin_primary_only_fraction_of_raw"] >= 0.7
    results["goal_met_with_shading"] = results["thin_fraction_of_raw"] >= 0.7
    print(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
