"""Motion blur: what it costs, and what sampling time jointly with film and lens buys.

Prints one JSON object with two studies on showcase.toml (thin lens, f/2.8):

- ``speed``: samples/s of the scene with motion blur on (the in-focus red
  sphere, the near blue one and the far white one moving, the camera rising;
  shutter 1/20 s) against the same scene still, same model, spp, sampler and
  threads; best of ``--repeats`` runs of each, interleaved (the machine is
  shared). Goal: ratio >= 0.8. ``ratio_cpu_time`` is the same from samples
  per second of process CPU time, which other processes on a loaded machine
  disturb far less than wall time.
- ``speed_one_mover``: the same with only the in-focus red sphere moving (no
  camera motion): a scene where most of what is seen stands still.
  Where the time goes: moving geometry sits in an Embree scene of its own,
  asked only about the rays that may meet it (moving spheres: each where it
  is at the ray's time; other movers: their swept boxes); each Embree scene
  costs a fixed amount per 16-ray packet whatever it holds. Here 24 % of the
  camera packets are asked and 97 % of those meet a sphere; the rest of the
  cost is Embree's second traversal, the culling test and drawing times.
- ``joint_stratification`` (showcase) and ``joint_stratification_streaks``
  (only motion and defocus: five small lamps before, at and behind focus,
  each moving its own way, on black): RMSE at 64 spp against a high-spp reference of
  the same moving scene (defocus and motion), for the sobol sampler as the
  render draws it (film and lens from one Owen-scrambled Sobol' sequence,
  dimensions 0-3, and each pixel's time from the index, i / spp,
  Owen-scrambled: film and time one (0,m,3)-net) against padding (film, lens
  and time each from their own scrambled Sobol' points, paired at random per
  pixel: ``SAMPLER_SOBOL_PADDED``), mean RMSE over ``--seeds`` seeds. Goal:
  padded / joint >= 1.3. ``ratio_time_net``: the same with
  ``SAMPLER_SOBOL_TIME_NET``, which is what the render's sobol now draws for a
  whole pixel, so it equals ``ratio`` (kept for comparison with earlier runs:
  before the render took it, sobol drew time from Sobol' dimension 6 for every
  pixel, as an adaptive pass continuing a pixel still does, and ``ratio`` on
  the showcase was 1.208 against 1.344 for the time net in one run; 1.335
  for the time net as the default, ten scenes 1.27-1.52, geometric mean 1.40).
- ``joint_stratification_sweep``: the same ratio on three large emissive
  spheres (before, at and behind focus) moving on black, over the shutter
  (streak length) and the f-number (defocus blur), with the streak and blur
  each sphere makes, in px. Joint stratification pays where the pixel's
  integrand depends on film, lens and time at comparable scales: when a
  streak or a blur spans many pixels, the integrand hardly depends on the film
  position and each dimension's own stratification already does the work.

Usage: python bench/bench_motion.py [--threads T] [--repeats R] [--seeds S] [--reference-spp N]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from lenscompare import _native
from lenscompare._native import diagnostics
from lenscompare.cameras import camera_for
from lenscompare.native_scene import build_native_scene
from lenscompare.render import render
from lenscompare.scene import load_scene

SCENE = Path(__file__).resolve().parent.parent / "reference_scenes" / "showcase.toml"
SHUTTER_S = (0.0, 0.05)


def moving(scene):
    """Showcase with three spheres moving (in focus, before and behind focus) and the camera rising."""
    velocities = {1: (2.0, 0.0, 0.0), 2: (0.0, 0.5, -2.0), 3: (-3.0, 0.0, 0.0)}
    objects = tuple(replace(o, velocity=velocities.get(i, (0.0, 0.0, 0.0))) for i, o in enumerate(scene.objects))
    return replace(scene, objects=objects).with_camera(velocity=(0.0, 0.2, 0.0)).with_render(shutter_s=SHUTTER_S)


def one_mover(scene):
    """Showcase with only the in-focus red sphere moving (2 m/s sideways), the camera still."""
    objects = tuple(replace(o, velocity=(2.0, 0.0, 0.0) if i == 1 else (0.0, 0.0, 0.0))
                    for i, o in enumerate(scene.objects))
    return replace(scene, objects=objects).with_render(shutter_s=SHUTTER_S)


def streaks(still):
    """Five lamps (before, at and behind the 3 m focus) moving on black, through the showcase camera."""
    from lenscompare.scene import EmissiveMaterial, Sphere
    lamps = [((-0.8, 0.5, 1.5), (3.0, 1.0, 0.0)), ((0.2, 0.3, 2.0), (-2.0, 2.0, 1.0)), ((0.0, 0.35, 3.0), (4.0, 0.0, 0.0)),
             ((0.9, 0.9, 6.0), (0.0, -5.0, 0.0)), ((-1.2, 1.2, 9.0), (6.0, 3.0, -4.0))]
    objects = tuple(Sphere(c, 0.06, "lamp", velocity=v) for c, v in lamps)
    return replace(still, objects=objects, lights=(), background=(0.0, 0.0, 0.0),
                   materials={"lamp": EmissiveMaterial("lamp", (4.0, 3.2, 1.8))}).with_render(shutter_s=SHUTTER_S)


def discs(still, *, shutter_s: float, f_number: float):
    """Three emissive spheres (before, at and behind the 3 m focus) moving on black: edges that
    are defocused and motion blurred at once, no shading or shadows."""
    from lenscompare.scene import EmissiveMaterial, Sphere
    balls = [((-0.7, 0.5, 1.6), 0.12, (3.0, 1.0, 0.0)), ((0.1, 0.35, 3.0), 0.25, (-4.0, 2.0, 0.0)),
             ((1.2, 0.8, 6.0), 0.5, (0.0, -6.0, 0.0))]
    objects = tuple(Sphere(c, r, "lamp", velocity=v) for c, r, v in balls)
    return replace(still, objects=objects, lights=(), background=(0.0, 0.0, 0.0),
                   materials={"lamp": EmissiveMaterial("lamp", (1.0, 0.8, 0.5))}).with_render(
        shutter_s=(0.0, shutter_s)).with_camera(f_number=f_number)


def blur_and_streak_px(scene) -> dict:
    """Each sphere's defocus blur (thin-lens circle of confusion, eq. 5) and streak (v T projected
    at its distance, thin-lens magnification), in px."""
    from lenscompare.optics import circle_of_confusion_mm, focus_film_distance_mm
    cam = scene.camera
    pixel_mm = cam.film_mm[0] / cam.resolution[0]
    film_m = focus_film_distance_mm(cam.focus_distance_m * 1000.0, cam.focal_length_mm) / 1000.0
    t_s = scene.render.shutter_s[1] - scene.render.shutter_s[0]
    out = []
    for o in scene.objects:
        z_m = o.center[2] - cam.position[2]
        coc = circle_of_confusion_mm(z_m * 1000.0, focus_distance_mm=cam.focus_distance_m * 1000.0,
                                     focal_length_mm=cam.focal_length_mm,
                                     aperture_diameter_mm=cam.focal_length_mm / cam.f_number)
        streak_mm = float(np.hypot(o.velocity[0], o.velocity[1])) * t_s * film_m / z_m * 1000.0
        out.append({"blur_px": round(coc / pixel_mm, 2), "streak_px": round(streak_mm / pixel_mm, 2)})
    return out


def speed(still, moved, *, spp: int, threads: int, repeats: int) -> dict:
    rates = {"still": [], "moving": []}
    cpu_rates = {"still": [], "moving": []}  # samples per second of process CPU time: steadier on a shared machine
    for _ in range(repeats):
        for name, scene in (("still", still), ("moving", moved)):
            cpu_start_s = time.process_time()
            image = render(scene, model="thin", spp=spp, sampler="sobol", seed=1, threads=threads, progress=False)
            cpu_s = time.process_time() - cpu_start_s
            rates[name].append(image.metadata["samples_per_second"])
            cpu_rates[name].append(scene.camera.width_px * scene.camera.height_px * spp / cpu_s)
    best = {name: max(values) for name, values in rates.items()}
    best_cpu = {name: max(values) for name, values in cpu_rates.items()}
    return {"spp": spp, "resolution": list(still.camera.resolution), "samples_per_second_still": best["still"],
            "samples_per_second_moving": best["moving"], "ratio": best["moving"] / best["still"],
            "ratio_cpu_time": best_cpu["moving"] / best_cpu["still"],
            "runs": rates, "goal_ratio": 0.8}


def render_with_code(scene, sampler_code: int, *, spp: int, seed: int, threads: int) -> np.ndarray:
    """A thin-lens render with any native sampler code (the padded one is not offered to users)."""
    camera = camera_for(scene, "thin").native(disk_mapping=scene.render.disk_mapping)
    native_scene = build_native_scene(scene)
    height, width = scene.camera.height_px, scene.camera.width_px
    out = np.zeros((height, width, 3), dtype=np.float32)
    _native.render_rows(native_scene, camera, spp, sampler_code, seed, threads, 0, height, out)
    return out


def joint_stratification(moved, *, spp: int, seeds: int, reference_spp: int, threads: int) -> dict:
    reference = render_with_code(moved, _native.SAMPLER_SOBOL, spp=reference_spp, seed=999, threads=threads)
    errors = {"joint": [], "padded": [], "time_net": []}
    for seed in range(seeds):
        for name, code in (("joint", _native.SAMPLER_SOBOL), ("padded", diagnostics.SAMPLER_SOBOL_PADDED),
                           ("time_net", diagnostics.SAMPLER_SOBOL_TIME_NET)):
            image = render_with_code(moved, code, spp=spp, seed=seed, threads=threads)
            errors[name].append(float(np.sqrt(np.mean((image.astype(np.float64) - reference) ** 2))))
    mean = {name: float(np.mean(values)) for name, values in errors.items()}
    return {"spp": spp, "reference_spp": reference_spp, "resolution": list(moved.camera.resolution),
            "rmse_joint": mean["joint"], "rmse_padded": mean["padded"], "ratio": mean["padded"] / mean["joint"],
            "rmse_time_net": mean["time_net"], "ratio_time_net": mean["padded"] / mean["time_net"],
            "rmse_per_seed": errors, "goal_ratio": 1.3}


def sweep(still, *, spp: int, seeds: int, reference_spp: int, threads: int) -> list:
    rows = []
    for shutter_s in (0.005, 0.01, 0.02, 0.05):
        for f_number in (2.8, 8.0):
            scene = discs(still, shutter_s=shutter_s, f_number=f_number)
            study = joint_stratification(scene, spp=spp, seeds=seeds, reference_spp=reference_spp, threads=threads)
            rows.append({"shutter_s": shutter_s, "f_number": f_number, "spheres": blur_and_streak_px(scene),
                         "ratio": study["ratio"], "ratio_time_net": study["ratio_time_net"],
                         "rmse_joint": study["rmse_joint"], "rmse_time_net": study["rmse_time_net"],
                         "rmse_padded": study["rmse_padded"]})
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--threads", type=int, default=os.cpu_count())
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--seeds", type=int, default=4)
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--reference-spp", type=int, default=4096)
    parser.add_argument("--speed-only", action="store_true", help="the samples/s ratios alone (a minute, not an hour)")
    args = parser.parse_args()

    still = load_scene(SCENE)
    moved = moving(still)
    small = moving(still.with_camera(resolution=(180, 120)))
    result = {
        "scene": str(SCENE.name),
        "shutter_s": list(SHUTTER_S),
        "threads": args.threads,
        "machine": platform.machine(),
        "cpu_count": os.cpu_count(),
        "speed": speed(still, moved, spp=args.spp, threads=args.threads, repeats=args.repeats),
        "speed_one_mover": speed(still, one_mover(still), spp=args.spp, threads=args.threads, repeats=args.repeats),
    }
    if not args.speed_only:
        result.update(stratification_studies(still, small, args))
    print(json.dumps(result, indent=2))


def stratification_studies(still, small, args) -> dict:
    """RMSE at args.spp, padded against joint sobol, on the moving scenes."""
    return {
        "joint_stratification": joint_stratification(small, spp=args.spp, seeds=args.seeds,
                                                     reference_spp=args.reference_spp, threads=args.threads),
        "joint_stratification_streaks": joint_stratification(streaks(still.with_camera(resolution=(180, 120))),
                                                             spp=args.spp, seeds=args.seeds,
                                                             reference_spp=args.reference_spp, threads=args.threads),
        "joint_stratification_sweep": sweep(still.with_camera(resolution=(180, 120)), spp=args.spp, seeds=args.seeds,
                                            reference_spp=args.reference_spp, threads=args.threads),
    }


if __name__ == "__main__":
    main()
