"""``lenscompare mitsuba SCENE -o OUT.exr``: the scene rendered by Mitsuba 3.

Same output contract as ``lenscompare povray``: a linear float EXR (channels R,
G, B) written atomically, and with ``--json`` one JSON object on stdout with at
least ``model``, ``spp``, ``seconds``, ``samples_per_second`` and ``output``.
Pinhole and thin lens only; thick / lens exit 2, as does a lit scene whose
lights have no inverse-square falloff. Mitsuba missing or failing exits 1.
"""

from __future__ import annotations

import json
from ..image import write_exr
from ..mitsuba import MAX_MITSUBA_SEED, MITSUBA_SAMPLERS, MITSUBA_VARIANTS, render_mitsuba
from ..scene import MODELS
from . import COMMAND_HELP
from ._options import SCENE_HELP, SPP, check_output_suffix, integer_option, load_scene_argument, with_lens_option

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "mitsuba", help=COMMAND_HELP["mitsuba"],
        description="Render SCENE with Mitsuba 3 (the mitsuba package) through the thin lens or the pinhole into a "
                    "linear float EXR, from the same XML that 'lenscompare export --to mitsuba' writes. Lit scenes "
                    "need falloff = \"inverse_square\" on their lights.")
    p.add_argument("scene", metavar="SCENE.toml", help=SCENE_HELP)
    p.add_argument("-o", "--output", required=True, metavar="OUT.exr")
    p.add_argument("--model", choices=MODELS, help="camera model: thin or pinhole (default: the scene's)")
    p.add_argument("--lens", metavar="NAME|PATH", help="lens prescription whose focal length to use")
    p.add_argument("--spp", type=SPP, help="samples per pixel (default: the scene's render.spp)")
    p.add_argument("--seed", type=integer_option(minimum=0, maximum=MAX_MITSUBA_SEED),
                   help="sampler seed, 0 to 2^32 - 1 (default: the scene's render.seed)")
    p.add_argument("--variant", choices=MITSUBA_VARIANTS, default="scalar_rgb",
                   help="Mitsuba variant (default scalar_rgb; llvm_ad_rgb needs DRJIT_LIBLLVM_PATH)")
    p.add_argument("--sampler", choices=MITSUBA_SAMPLERS, default="independent",
                   help="Mitsuba's sampler (default independent; stratified is the native jittered's construction "
                        "and takes a square --spp)")
    p.add_argument("--json", action="store_true", help="print one JSON object describing the render")
    p.set_defaults(run=run)


def run(args) -> int:
    output = check_output_suffix(args.output, ".exr")  # say so before a long render, not after
    scene = with_lens_option(load_scene_argument(args.scene), args.lens)
    image = render_mitsuba(scene, model=args.model, spp=args.spp, seed=args.seed, variant=args.variant,
                           sampler=args.sampler)
    write_exr(output, image, final=True)
    if args.json:
        print(json.dumps({**image.metadata, "output": str(args.output)}))
    return 0
