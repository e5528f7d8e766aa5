"""``lenscompare render SCENE -o OUT.exr``: a native render to linear EXR."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from ..errors import InputError
from ..image import write_exr
from ..plan import render_planned
from ..render import render
from ..scene import MODELS, SAMPLERS, load_scene

__all__ = ["add_parser", "run"]


def positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}")
    return value


def non_negative_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected an integer >= 0, got {text!r}")
    return value


def add_parser(subparsers) -> None:
    p = subparsers.add_parser("render", help="render a scene with the native tracer",
                              description="Render SCENE with the native tracer into a linear float EXR.")
    p.add_argument("scene", metavar="SCENE.toml")
    p.add_argument("-o", "--output", required=True, metavar="OUT.exr")
    p.add_argument("--model", choices=MODELS + ("auto",),
                   help="camera model (default: the scene's); auto: the cheapest within tolerance (see plan)")
    p.add_argument("--lens", metavar="NAME|PATH", help="lens prescription (shipped name or file)")
    p.add_argument("--spp", type=positive_int, help="samples per pixel")
    p.add_argument("--sampler", choices=SAMPLERS)
    p.add_argument("--seed", type=non_negative_int)
    p.add_argument("--adaptive", action="store_true", default=None,
                   help="spp is the mean: a first pass finds the noisy pixels, the rest of the samples go there")
    p.add_argument("--diffraction", action="store_true", default=None,
                   help="apply the aperture's diffraction PSF (400-700 nm) to the image")
    p.add_argument("--threads", type=positive_int, help="worker threads (default: all cores)")
    p.add_argument("--json", action="store_true", help="print one JSON object describing the render")
    p.set_defaults(run=run)


def run(args) -> int:
    if not str(args.output).lower().endswith(".exr"):
        raise InputError("-o", f"expected an .exr file name, got {args.output!r}")
    scene = load_scene(args.scene)
    if args.lens is not None:
        # A path on the command line is relative to where the user is, not to the scene file.
        lens = args.lens
        if Path(lens).exists():
            lens = str(Path(lens).resolve())
        scene = scene.with_camera(lens=lens)
    options = dict(spp=args.spp, sampler=args.sampler, seed=args.seed, threads=args.threads, adaptive=args.adaptive,
                   diffraction=args.diffraction)
    if args.model == "auto":  # simulate only what the scene calls for (default tolerances)
        image = render_planned(scene, **options)
    else:
        image = render(scene, model=args.model, **options)
    write_exr(args.output, image)
    if args.json:
        print(json.dumps({**image.metadata, "output": str(args.output)}))
    return 0
