"""The postfilter model against the thin lens: speed at equal spp, time to 1 %
relative RMSE, blur-disk sizes and the error at occlusion edges.

Prints one JSON object:

- ``speed``: showcase.toml (360x240) rendered through the thin lens and the
  postfilter at the same requested spp (16, 64, 256), alternating, best of
  ``--repeats``. The postfilter's pinhole pass draws at most min(spp, 16) film
  samples (``pinhole_spp``): 2 everywhere, that many on silhouettes and where
  those 2 show an edge (lenscompare.postfilter.refine; ``pinhole_mean_spp``);
  its seconds include the pinhole pass, the depth buffer and the spread. Goal:
  >= 5x the thin lens's speed. ``uniform_pass_*``: min(spp, 16) in every pixel
  (the model before the refined pass), timed in the same alternation. ``per_pixel_*``: the
  opt-in per-pixel pinhole counts (lenscompare.postfilter.samples; less
  accurate, see bench/study_pinhole_counts.py), timed in the same alternation.
- ``time_to_1_percent``: the fewest seconds each needs to come within 1 %
  relative RMSE of its own converged image (thin: 2048 spp; postfilter: a
  1024-spp pinhole pass spread the same way), spp doubling from 1; the
  postfilter's pinhole pass here may exceed render's 16-spp cap (its parts
  composed: pinhole render + depth buffer + spread, all timed).
- ``blur_disks``: second-moment diameters on blur_disks.toml (64 spp) against
  eq. 5, postfilter and thin lens, %.
- ``edges``: relative RMSE against the converged thin lens in the band of
  ``BAND_PX`` px round the occlusion edges (lenscompare.postfilter.edges) and
  elsewhere, for the postfilter (converged pinhole; and the render at 64 spp,
  refined and uniform pass) and the thin lens at 64 spp, on showcase and on
  showcase at f/1.4 focused on the near blue sphere;
  with the planner's predicted edge error.

Usage: python bench/bench_postfilter.py [--repeats R] [--threads T] [--speed-only]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from types import SimpleNamespace

import numpy as np

from lenscompare.cameras import camera_for
from lenscompare.measure import measure_blur_disks
from lenscompare.metrics import relative_rmse
from lenscompare.postfilter import (BAND_PX, MAX_PINHOLE_SPP, METHOD, depth_buffer_m, edge_band, edge_band_error,
                                    postfilter_edge_error, signed_coc_px, spread)
from lenscompare.postfilter.refine import RULE as REFINE_RULE
from lenscompare.postfilter.samples import RULE as PINHOLE_RULE
from lenscompare.reference_scenes import shipped_scene
from lenscompare.render import render
from lenscompare.scene import load_scene

REFERENCE_THIN_SPP = 2048
REFERENCE_PINHOLE_SPP = 1024
REFERENCE_SEED = 11
PINHOLE_PASS = (f"{REFINE_RULE}; no lens samples (uniform_pass_*: min(spp, {MAX_PINHOLE_SPP}) everywhere; "
                f"per_pixel_*: {PINHOLE_RULE})")


def best_render(scene, model, spp, threads, repeats):
    images = [render(scene, model=model, spp=spp, threads=threads, progress=False) for _ in range(repeats)]
    return min(images, key=lambda image: image.metadata["seconds"])


def composed_postfilter(scene, pinhole_spp, threads, seed=0):
    """The postfilter of a pinhole pass of any spp (its public parts, without
    render's 16-spp cap): image and seconds (pass + depth + spread)."""
    start = time.perf_counter()
    pinhole = render(scene, model="pinhole", spp=pinhole_spp, seed=seed, threads=threads, progress=False)
    depth = depth_buffer_m(scene, camera_for(scene, "pinhole"), threads=threads)
    image = spread(pinhole.pixels, depth, camera_for(scene, "thin"), threads=threads)[0]
    return image, time.perf_counter() - start


def converged_postfilter(scene, threads):
    return composed_postfilter(scene, REFERENCE_PINHOLE_SPP, threads, seed=REFERENCE_SEED)[0]


def speed(scene, threads, repeats):
    rows = []
    for spp in (16, 64, 256):
        thin_s, post_s, uniform_s, per_pixel_s, post = [], [], [], [], None
        for _ in range(repeats):  # alternating, so a loaded machine slows all alike
            thin_s.append(render(scene, model="thin", spp=spp, threads=threads, progress=False).metadata["seconds"])
            image = render(scene, model="postfilter", spp=spp, threads=threads, progress=False)
            post_s.append(image.metadata["seconds"])
            post = image if post is None or image.metadata["seconds"] <= min(post_s) else post
            uniform_s.append(render(scene, model="postfilter", spp=spp, threads=threads, progress=False,
                                    postfilter_uniform_pass=True).metadata["seconds"])
            per_pixel = render(scene, model="postfilter", spp=spp, threads=threads, progress=False,
                               postfilter_per_pixel_spp=True)
            per_pixel_s.append(per_pixel.metadata["seconds"])
        info = post.metadata["postfilter"]
        rows.append({"spp": spp, "pinhole_spp": info["pinhole_spp"],
                     "pinhole_mean_spp": info.get("pinhole_mean_spp", info["pinhole_spp"]),
                     "thin_seconds_best": min(thin_s),
                     "postfilter_seconds_best": min(post_s), "speed_ratio": min(thin_s) / min(post_s),
                     "uniform_pass_seconds_best": min(uniform_s),
                     "uniform_pass_speed_ratio": min(thin_s) / min(uniform_s),
                     "per_pixel_pinhole_mean_spp": per_pixel.metadata["postfilter"]["pinhole_mean_spp"],
                     "per_pixel_seconds_best": min(per_pixel_s),
                     "per_pixel_speed_ratio": min(thin_s) / min(per_pixel_s),
                     "goal_met": min(thin_s) / min(post_s) >= 5.0,
                     "postfilter_parts_seconds": {k: info[k] for k in ("pinhole_seconds", "depth_seconds",
                                                                       "filter_seconds")},
                     "layers": info["layers"]})
    return rows


def time_to_one_percent(scene, thin_reference, post_reference, threads, repeats):
    out = {}
    for model, reference in (("thin", thin_reference), ("postfilter", post_reference)):
        spp, trail = 1, []
        while spp <= 1024:
            if model == "thin":
                image = best_render(scene, model, spp, threads, repeats)
                pixels, seconds = image.pixels, image.metadata["seconds"]
            else:  # the pinhole pass at this spp, even beyond render's cap
                runs = [composed_postfilter(scene, spp, threads) for _ in range(repeats)]
                pixels, seconds = min(runs, key=lambda run: run[1])
            error = relative_rmse(reference, pixels)
            trail.append({"spp": spp, "relative_rmse": error, "seconds": seconds})
            if error <= 0.01:
                break
            spp *= 2
        reached = trail[-1]["relative_rmse"] <= 0.01
        out[model] = {"seconds": trail[-1]["seconds"] if reached else None, "spp": trail[-1]["spp"] if reached else None,
                      "trail": trail,
                      "note": None if reached else f"not within 1 % at the largest spp tried ({trail[-1]['spp']})"}
    if out["thin"]["seconds"] and out["postfilter"]["seconds"]:
        out["ratio"] = out["thin"]["seconds"] / out["postfilter"]["seconds"]
    return out


def blur_disks(threads):
    scene = load_scene(shipped_scene("blur_disks"))
    runs = [SimpleNamespace(label=m, image=render(scene, model=m, spp=64, threads=threads, progress=False))
            for m in ("postfilter", "thin")]
    runs.append(SimpleNamespace(label="uniform", image=render(scene, model="postfilter", spp=64, threads=threads,
                                                              progress=False, postfilter_uniform_pass=True)))
    table = measure_blur_disks(scene, runs)
    rows = []
    for post, thin, uniform in zip(table["renders"]["postfilter"], table["renders"]["thin"],
                                   table["renders"]["uniform"]):
        if post is None or thin is None:
            continue
        rows.append({"depth_m": post["depth_m"], "eq5_px": post["eq5_px"], "postfilter_px": post["measured_px"],
                     "postfilter_uniform_pass_px": uniform["measured_px"] if uniform else None,
                     "thin_px": thin["measured_px"], "postfilter_vs_eq5_percent": post["departure_from_eq5_percent"],
                     "thin_vs_eq5_percent": thin["departure_from_eq5_percent"],
                     "postfilter_vs_thin_percent": 100.0 * (post["measured_px"] / thin["measured_px"] - 1.0)})
    return rows


def edges(scene, thin_reference, post_converged, threads):
    depth = depth_buffer_m(scene, camera_for(scene, "pinhole"), threads=threads)
    coc = signed_coc_px(depth, camera_for(scene, "thin"))
    band = edge_band(depth, coc)
    thin64 = render(scene, model="thin", spp=64, threads=threads, progress=False).pixels
    at_64 = {}
    for label, uniform in (("postfilter_64spp", False), ("postfilter_uniform_pass_64spp", True)):
        pixels = render(scene, model="postfilter", spp=64, threads=threads, progress=False,
                        postfilter_uniform_pass=uniform).pixels
        at_64[label] = {**edge_band_error(thin_reference, pixels, band),
                        "whole_relative_rmse": relative_rmse(thin_reference, pixels)}
    return {**at_64,"max_coc_px": float(np.abs(coc).max()), "predicted": postfilter_edge_error(scene).to_json(),
            "postfilter_converged": {**edge_band_error(thin_reference, post_converged, band),
                                     "whole_relative_rmse": relative_rmse(thin_reference, post_converged)},
            "thin_64spp": {**edge_band_error(thin_reference, thin64, band),
                           "whole_relative_rmse": relative_rmse(thin_reference, thin64)}}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--threads", type=int, default=os.cpu_count())
    parser.add_argument("--speed-only", action="store_true", help="only the speed rows (no references)")
    args = parser.parse_args()

    showcase = load_scene(shipped_scene("showcase"))
    if args.speed_only:
        print(json.dumps({"benchmark": "postfilter", "scene": "showcase", "threads": args.threads,
                          "pinhole_pass": PINHOLE_PASS, "speed": speed(showcase, args.threads, args.repeats)},
                         indent=2))
        return
    thin_reference = render(showcase, model="thin", spp=REFERENCE_THIN_SPP, seed=REFERENCE_SEED,
                            threads=args.threads, progress=False).pixels
    post_reference = converged_postfilter(showcase, args.threads)
    results = {"benchmark": "postfilter", "scene": "showcase", "resolution": list(showcase.camera.resolution),
               "threads": args.threads, "machine": platform.machine(), "cpu_count": os.cpu_count(),
               "method": METHOD, "pinhole_pass": PINHOLE_PASS,
               "speed": speed(showcase, args.threads, args.repeats),
               "time_to_1_percent": time_to_one_percent(showcase, thin_reference, post_reference, args.threads,
                                                        args.repeats),
               "blur_disks": blur_disks(args.threads),
               "edges": {"band_px": BAND_PX, "showcase": edges(showcase, thin_reference, post_reference, args.threads)}}
    near = showcase.with_camera(f_number=1.4, focus_distance_m=1.9)
    near_reference = render(near, model="thin", spp=REFERENCE_THIN_SPP, seed=REFERENCE_SEED, threads=args.threads,
                            progress=False).pixels
    results["edges"]["showcase_f1.4_focus_1.9m"] = edges(near, near_reference, converged_postfilter(near, args.threads),
                                                         args.threads)
    print(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
