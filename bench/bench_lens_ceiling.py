"""How close the traced lens system can come to the pinhole's samples/s (issue 20's 0.85x).

A lens-system sample does the pinhole's work (Embree, shading, shadow rays,
film) plus its camera's rays: film point, exit-pupil pick, aim, the trace
through every surface and the step to the world. If the rest cost exactly
what the pinhole's does, the lens system's samples/s could reach at most

    ceiling = P / (P - p + L)

of the pinhole's, P the pinhole's whole sample, p the pinhole camera's own
ray and L the lens camera's ray, all in one thread's CPU time. This prints
those figures from one process, the measured ratio beside them, and the
budget L would have to meet for 0.85x. On showcase.toml through the Double
Gauss wide open, one thread (so CPU time is the render's time), best of
``--repeat`` alternating rounds:

- P: a one-thread render's seconds per sample (``metadata["seconds"]``, the
  render alone), pinhole and lens system traced alternating;
- L and p: ``diagnostics.lens_stage_seconds`` on render-order samples
  (``render_order.py``: 16-pixel tiles, ``--camera-spp`` samples of a pixel
  in a row, a few dozen batches at a time so that they stay in cache): the
  lens camera's picks and aim, its batch trace alone and its float rows
  whole (L), and the pinhole's rows (p), as the render's packets take them.

Prints one JSON object. Not a test. Usage::

    python bench/bench_lens_ceiling.py [--spp 64] [--repeat 7]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from lenscompare._native import diagnostics  # noqa: E402
from lenscompare.cameras import camera_for  # noqa: E402
from lenscompare.render import render  # noqa: E402
from lenscompare.scene import load_scene  # noqa: E402
from render_order import render_order_samples  # noqa: E402

LENS = "dgauss.50mm"
GOAL = 0.85


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--spp", type=int, default=64, help="samples per pixel of the one-thread renders")
    parser.add_argument("--camera-spp", type=int, default=4, help="samples per pixel of the camera-only timings")
    parser.add_argument("--repeat", type=int, default=7, help="alternating rounds; the best of each counts")
    args = parser.parse_args()

    scene = load_scene(ROOT / "reference_scenes" / "showcase.toml").with_camera(lens=LENS, f_number=None)
    width_px, height_px = scene.camera.resolution
    samples = width_px * height_px * args.spp
    lens_camera = camera_for(scene, "lens").native()
    pinhole_camera = camera_for(scene, "pinhole").native()
    raster, lens = render_order_samples(width_px, height_px, samples_per_pixel=args.camera_spp, seed=5)
    rays = len(raster)

    render_s = {"pinhole": float("inf"), "lens": float("inf")}
    stage_s = {"sample": float("inf"), "trace": float("inf"), "whole": float("inf"), "pinhole": float("inf")}
    for _ in range(args.repeat):
        for model in render_s:
            image = render(scene, model=model, spp=args.spp, threads=1, progress=False)
            render_s[model] = min(render_s[model], image.metadata["seconds"])
        for stage, seconds in zip(stage_s, diagnostics.lens_stage_seconds(lens_camera, pinhole_camera, raster, lens)):
            stage_s[stage] = min(stage_s[stage], seconds)

    pinhole_ns = render_s["pinhole"] / samples * 1e9
    lens_ns = render_s["lens"] / samples * 1e9
    stage_ns = {stage: seconds / rays * 1e9 for stage, seconds in stage_s.items()}
    pinhole_ray_ns = stage_ns["pinhole"]
    lens_ray_ns = stage_ns["whole"]
    # The lens camera's whole ray may cost at most this for GOAL, the rest of a sample being the pinhole's.
    budget_ns = pinhole_ns / GOAL - pinhole_ns + pinhole_ray_ns
    print(json.dumps({
        "benchmark": "the traced lens system's ceiling against the pinhole, one thread, CPU time",
        "scene": "showcase",
        "lens": LENS,
        "resolution": [width_px, height_px],
        "spp": args.spp,
        "camera_rays": rays,
        "repeat": args.repeat,
        "pinhole_ns_per_sample": pinhole_ns,
        "lens_ns_per_sample": lens_ns,
        "measured_lens_over_pinhole": pinhole_ns / lens_ns,
        "lens_camera_ns_per_ray": {
            "picks_and_aim": stage_ns["sample"],
            "trace": stage_ns["trace"],
            # The step to the world, less what running the stages together saves: may be negative.
            "whole_less_the_stages": stage_ns["whole"] - stage_ns["sample"] - stage_ns["trace"],
            "whole": lens_ray_ns,
        },
        "pinhole_camera_ns_per_ray": pinhole_ray_ns,
        "lens_camera_over_pinhole_sample": lens_ray_ns / pinhole_ns,
        "ceiling_lens_over_pinhole": pinhole_ns / (pinhole_ns - pinhole_ray_ns + lens_ray_ns),
        "goal": GOAL,
        "lens_camera_budget_ns_for_goal": budget_ns,
        "trace_alone_over_budget": stage_ns["trace"] / budget_ns,
    }, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
