"""Cost of applying diffraction to a 1920x1080 render, against the render.

Prints one JSON object. The scene is showcase.toml at 1920x1080 rendered
through the thin lens at 16 spp; diffraction is the PSF's computation (pupil
FFT, pixel kernel over 31 wavelengths) plus the FFT convolution of the image
(and of its variance), as ``render(..., diffraction=True)`` runs it. Two films:
the scene's 36 mm (18.75 µm pixels) at its f/2.8, and 7.68 mm (4 µm pixels)
at f/22 (the planner's diffraction case: a 7-pixel Airy disk, a kernel
~290 px across). The PSF cache is cleared before every diffraction (cold: what
one render pays). Render and diffraction alternate, best of ``--repeats``
each, so that a loaded machine slows both alike. Goal: diffraction <= 10 % of
the render.

Usage: python bench/bench_diffraction.py [--repeats R] [--threads T]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from pathlib import Path

from lenscompare.diffraction import diffract, diffraction_aperture
from lenscompare.optics.diffraction import pupil_psf
from lenscompare.render import render
from lenscompare.scene import load_scene

SCENE = Path(__file__).resolve().parent.parent / "reference_scenes" / "showcase.toml"
CASES = {"film_36mm_f2.8": dict(film_mm=(36.0, 20.25), f_number=2.8),
         "pixels_4um_f22": dict(film_mm=(7.68, 4.32), f_number=22.0)}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--threads", type=int, default=os.cpu_count())
    args = parser.parse_args()

    results = {"benchmark": "diffraction", "scene": "showcase", "resolution": [1920, 1080], "spp": 16,
               "model": "thin", "threads": args.threads, "machine": platform.machine(), "cpu_count": os.cpu_count(),
               "goal_fraction_of_render": 0.10, "cases": {}}
    for name, camera in CASES.items():
        scene = load_scene(SCENE).with_camera(resolution=(1920, 1080), **camera)
        render_s, diffract_s, info = [], [], None
        for _ in range(args.repeats):
            start = time.perf_counter()
            image = render(scene, model="thin", spp=16, threads=args.threads, progress=False)
            render_s.append(time.perf_counter() - start)
            pupil_psf.cache_clear()
            start = time.perf_counter()
            _, _, info = diffract(image.pixels, image.variance, diffraction_aperture(scene, image.camera))
            diffract_s.append(time.perf_counter() - start)
        results["cases"][name] = {
            "pixel_pitch_mm": image.camera.pixel_pitch_mm, "f_number": camera["f_number"],
            "airy_diameter_px_550nm": info["airy_diameter_px_550nm"], "kernel_radius_px": info["kernel_radius_px"],
            "render_seconds_best": min(render_s), "diffraction_seconds_best": min(diffract_s),
            "fraction_of_render": min(diffract_s) / min(render_s),
            "goal_met": min(diffract_s) / min(render_s) <= 0.10,
        }
    print(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
