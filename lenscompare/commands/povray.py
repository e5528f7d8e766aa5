"""``lenscompare povray SCENE -o OUT.exr``: the POV-Ray reference render of a scene.

Same output contract as ``lenscompare render``: a linear float EXR (channels R,
G, B) written atomically, and with ``--json`` one JSON object on stdout with at
least ``model``, ``spp``, ``seconds``, ``samples_per_second`` and ``output``.
POV-Ray renders the thin lens and the pinhole only; thick / lens exit 2. A
missing or failing POV-Ray exits 1 with POV-Ray's own last lines. A moving
scene is the average of ``--time-samples`` sub-frames (POV-Ray has no motion
blur of its own).
"""

from __future__ import annotations

import json

from ..image import write_exr
from ..povray import render_povray
from ..povray.runner import MAX_AUTO_TIME_SAMPLES, MAX_SUBFRAME_SPACING_PX, MAX_TIME_SAMPLES
from ..scene import MODELS
from . import COMMAND_HELP
from ._options import (
    POSITIVE,
    SCENE_HELP,
    SPP,
    THREADS,
    check_output_suffix,
    integer_option,
    load_scene_argument,
    with_lens_option,
)

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "povray", help=COMMAND_HELP["povray"],
        description="Render SCENE with POV-Ray 3.7 through the thin lens or the pinhole into a linear float EXR. "
                    "--spp is camera rays per pixel: the thin lens's blur_samples; for the pinhole rounded up "
                    "to n*n+1 (POV-Ray's anti-aliasing grid plus the centre ray, at most 82).")
    p.add_argument("scene", metavar="SCENE.toml", help=SCENE_HELP)
    p.add_argument("-o", "--output", required=True, metavar="OUT.exr")
    p.add_argument("--model", choices=MODELS, help="camera model: thin or pinhole (default: the scene's)")
    p.add_argument("--lens", metavar="NAME|PATH", help="lens prescription whose focal length to use")
    p.add_argument("--spp", type=SPP, help="camera rays per pixel (default: the scene's render.spp)")
    p.add_argument("--threads", type=THREADS, help="POV-Ray worker threads (default: all cores)")
    p.add_argument("--time-samples", type=integer_option(minimum=1, maximum=MAX_TIME_SAMPLES), metavar="K",
                   help="a moving scene (render.shutter, velocity): average K sub-frames at evenly spaced times, "
                        "each with spp/K rays per pixel (POV-Ray has no motion blur; default: enough that the "
                        f"longest streak's copies lie at most {MAX_SUBFRAME_SPACING_PX:g} px apart, at most "
                        f"{MAX_AUTO_TIME_SAMPLES})")
    p.add_argument("--povray", default="povray", metavar="BINARY", help="the POV-Ray binary (default: povray)")
    p.add_argument("--timeout", type=POSITIVE, metavar="SECONDS", help="stop POV-Ray after this long")
    p.add_argument("--json", action="store_true", help="print one JSON object describing the render")
    p.set_defaults(run=run)


def run(args) -> int:
    output = check_output_suffix(args.output, ".exr")  # say so before a long render, not after
    scene = with_lens_option(load_scene_argument(args.scene), args.lens)
    image = render_povray(scene, model=args.model, spp=args.spp, threads=args.threads, povray=args.povray,
                          timeout_s=args.timeout, time_samples=args.time_samples)
    write_exr(output, image, final=True)
    if args.json:
        print(json.dumps({**image.metadata, "output": str(args.output)}))
    return 0
