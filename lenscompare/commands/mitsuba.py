"""``lenscompare mitsuba SCENE -o OUT.exr``: the scene rendered by Mitsuba 3.

Same output contract as ``lenscompare povray``: a linear float EXR (channels R,
G, B) written atomically, and with ``--json`` one JSON object on stdout with at
least ``model``, ``spp``, ``seconds``, ``samples_per_second`` and ``output``.
Pinhole and thin lens only; thick / lens exit 2, as does a lit scene whose
lights have no inverse-square falloff. Mitsuba missing or failing exits 1.
"""

from __future__ import annotations

import json
from pathlib import Path

from ..errors import InputError
from ..image import write_exr
from ..mitsuba import MITSUBA_VARIANTS, render_mitsuba
from ..scene import MODELS, load_scene
from ._options import SEED, SPP

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "mitsuba", help="render a scene with Mitsuba 3 (a second independent reference)",
        description="Render SCENE with Mitsuba 3 (the mitsuba package) through the thin lens or the pinhole into a "
                    "linear float EXR, from the same XML that 'lenscompare export --to mitsuba' writes. Lit scenes "
                    "need falloff = \"inverse_square\" on their lights.")
    p.add_argument("scene", metavar="SCENE.toml")
    p.add_argument("-o", "--output", required=True, metavar="OUT.exr")
    p.add_argument("--model", choices=MODELS, help="camera model: thin or pinhole (default: the scene's)")
    p.add_argument("--lens", metavar="NAME|PATH", help="lens prescription whose focal length to use")
    p.add_argument("--spp", type=SPP, help="samples per pixel (default: the scene's render.spp)")
    p.add_argument("--seed", type=SEED, help="sampler seed (default: the scene's render.seed)")
    p.add_argument("--variant", choices=MITSUBA_VARIANTS, default="scalar_rgb",
                   help="Mitsuba variant (default scalar_rgb; llvm_ad_rgb needs DRJIT_LIBLLVM_PATH)")
    p.add_argument("--json", action="store_true", help="print one JSON object describing the render")
    p.set_defaults(run=run)


def run(args) -> int:
    if not str(args.output).lower().endswith(".exr"):
        raise InputError("-o", f"expected an .exr file name, got {args.output!r}")
    folder = Path(args.output).parent
    if not folder.is_dir():  # say so before a long render, not after
        raise InputError("-o", f"folder {str(folder)!r} for {str(args.output)!r} does not exist")
    if args.seed is not None and args.seed < 0:
        raise InputError("--seed", f"expected a non-negative integer, got {args.seed}")
    scene = load_scene(args.scene)
    if args.lens is not None:
        scene = scene.with_camera(lens=args.lens)
    image = render_mitsuba(scene, model=args.model, spp=args.spp, seed=args.seed, variant=args.variant)
    write_exr(args.output, image)
    if args.json:
        print(json.dumps({**image.metadata, "output": str(args.output)}))
    return 0
