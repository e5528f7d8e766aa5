"""``lenscompare measure IMAGE.exr --scene SCENE.toml``: any renderer's image of a scene, judged.

Runs the scene's measurements (its ``measure = [...]``: blur disks against
equation 5 and the projection, distortion, vignetting, similarity) on the
image, each against a stated tolerance (:mod:`lenscompare.verdict`), and
exits like ``check``: 0 when every measurement holds, 1 when one fails (the
line names the quantity), 2 for bad input (an unreadable image, a size that
is not the scene's, a bad option).
"""

from __future__ import annotations

import argparse
import json

from ..image import read_exr
from ..scene import MODELS
from ..verdict import Tolerances, judge_image
from . import COMMAND_HELP
from ._options import POSITIVE, SCENE_HELP, THREADS, load_scene_argument, number_option, with_lens_option

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "measure", help=COMMAND_HELP["measure"],
        description="Run SCENE's measurements on IMAGE.exr (made by any renderer, at the scene's resolution, "
                    "linear RGB) against the expectations of the camera model it shows; exit 0 when all hold, "
                    "1 when any fails, 2 for bad input.")
    p.add_argument("image", metavar="IMAGE.exr")
    p.add_argument("--scene", required=True, metavar="SCENE.toml", help=SCENE_HELP)
    p.add_argument("--model", choices=MODELS, help="the camera model the image shows (default: the scene's)")
    p.add_argument("--lens", metavar="NAME|PATH", help="lens prescription (for model lens, or the focal length)")
    defaults = Tolerances()
    for name, help_text in (("blur_tolerance_percent", "blur-disk diameter against eq. 5"),
                            ("min_blur_px", "smallest expected disk that is judged"),
                            ("projection_tolerance_px", "point-source centroid against the projection"),
                            ("distortion_tolerance_percent", "radial distortion against the expectation"),
                            ("vignetting_tolerance", "relative illumination at 10 and 20 degrees"),
                            ("min_ssim", "SSIM against a native render")):
        p.add_argument("--" + name.replace("_", "-"), dest=name, type=number_option(maximum=1.0) if name == "min_ssim" else POSITIVE, default=getattr(defaults, name),
                       help=f"{help_text} (default {getattr(defaults, name):g})")
    p.add_argument("--threads", type=THREADS, default=None, help="threads for the native render of 'similarity'")
    p.add_argument("--json", action="store_true", help="print one JSON object with every verdict")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    scene = with_lens_option(load_scene_argument(args.scene), args.lens)
    image = read_exr(args.image)
    tolerances = Tolerances(**{k: getattr(args, k) for k in Tolerances.__dataclass_fields__})
    verdicts = judge_image(scene, image, model=args.model, tolerances=tolerances, source=str(args.image),
                           threads=args.threads)
    failed = sum(not v.passed for v in verdicts)
    if args.json:
        print(json.dumps({"image": str(args.image), "scene": scene.source, "model": args.model or scene.camera.model,
                          "passed": failed == 0,
                          "measurements": {v.measurement: {"passed": v.passed, "message": v.message}
                                           for v in verdicts}}))
    else:
        for v in verdicts:
            print(f"{'PASS' if v.passed else 'FAIL'}  {v.measurement}: {v.message}")
        print(f"{len(verdicts) - failed} passed, {failed} failed")
    return 1 if failed else 0
