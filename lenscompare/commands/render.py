"""``lenscompare render SCENE -o OUT.exr``: a native render to linear EXR."""

from __future__ import annotations

import json

from ..errors import InputError
from ..image import write_exr
from ..plan import render_planned
from ..render import render
from ..scene import LENS_RAYS, RENDER_MODELS, SAMPLERS
from . import COMMAND_HELP
from ._options import (
    SCENE_HELP,
    NON_NEGATIVE,
    SEED,
    SPP,
    THREADS,
    check_output_suffix,
    effect_list,
    load_scene_argument,
    with_lens_option,
)

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> None:
    p = subparsers.add_parser("render", help=COMMAND_HELP["render"],
                              description="Render SCENE with the native tracer into a linear float EXR.")
    p.add_argument("scene", metavar="SCENE.toml", help=SCENE_HELP)
    p.add_argument("-o", "--output", required=True, metavar="OUT.exr")
    p.add_argument("--model", choices=RENDER_MODELS + ("auto",),
                   help="camera model (default: the scene's); postfilter: a pinhole render spread by its depth "
                        "buffer (at most 16 spp drawn); auto: the cheapest within tolerance (see plan)")
    p.add_argument("--effects", type=effect_list, metavar="A,B,...",
                   help="render exactly these effects with a composite of cheap parts (defocus, distortion, "
                        "vignetting; diffraction as a post-filter); others need --model lens")
    p.add_argument("--tolerance-px", type=NON_NEGATIVE, default=0.5,
                   help="--model auto: largest blur/distortion left out (px)")
    p.add_argument("--tolerance-percent", type=NON_NEGATIVE, default=2.0,
                   help="--model auto: largest corner falloff left out (%%)")
    p.add_argument("--lens", metavar="NAME|PATH", help="lens prescription (shipped name or file)")
    p.add_argument("--spp", type=SPP, help="samples per pixel (1 to 2^20)")
    p.add_argument("--sampler", choices=SAMPLERS)
    p.add_argument("--seed", type=SEED, help="0 to 2^64 - 1")
    p.add_argument("--lens-rays", choices=LENS_RAYS,
                   help="--model lens: trace every sample's ray (traced, the default) or interpolate a "
                        "table of rays traced once (table: faster, rays within hundredths of a pixel)")
    p.add_argument("--lens-mirrors", action="store_true", default=None,
                   help="--model lens: a pixel and its mirror images across the film's centre lines share one "
                        "traced set of samples, reflected (about 1.5x faster; their noise is correlated)")
    p.add_argument("--adaptive", action="store_true", default=None,
                   help="spp is the mean: a first pass finds the noisy pixels, the rest of the samples go there")
    p.add_argument("--diffraction", action="store_true", default=None,
                   help="apply the aperture's diffraction PSF (400-700 nm) to the image")
    p.add_argument("--threads", type=THREADS, help="worker threads (default and at most: all cores)")
    p.add_argument("--json", action="store_true", help="print one JSON object describing the render")
    p.set_defaults(run=run)


def run(args) -> int:
    output = check_output_suffix(args.output, ".exr")  # before the work: a read-only folder fails now
    scene = with_lens_option(load_scene_argument(args.scene), args.lens)
    options = dict(spp=args.spp, sampler=args.sampler, seed=args.seed, threads=args.threads, adaptive=args.adaptive,
                   diffraction=args.diffraction, lens_rays=args.lens_rays,
                   lens_mirrors=args.lens_mirrors)
    if args.effects is not None and args.model is not None:
        raise InputError("--effects", f"renders a composite of exactly those effects; leave out --model {args.model}")
    if args.model == "auto":  # simulate only what the scene calls for
        image = render_planned(scene, tolerance_px=args.tolerance_px, tolerance_percent=args.tolerance_percent,
                               **options)
    else:
        image = render(scene, model=args.model, effects=args.effects, **options)
    write_exr(output, image, final=True)
    if args.json:
        print(json.dumps({**image.metadata, "output": str(args.output)}))
    return 0
