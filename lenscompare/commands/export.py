"""``lenscompare export SCENE --to povray|mitsuba|pbrt -o FILE``: the scene in another renderer's own format.

- ``povray``: POV-Ray 3.7 SDL, the very text ``lenscompare povray`` renders.
- ``mitsuba``: Mitsuba 3 XML, with its PLY meshes in ``<FILE stem>_meshes/``
  beside it; the very files ``lenscompare mitsuba`` renders (Mitsuba's
  ``load_file`` resolves them relative to the XML).
- ``pbrt``: pbrt-v4 scene text (and, for model ``lens``, the prescription as
  ``<FILE stem>.lens.dat`` beside it). Not rendered here: pbrt is not installed.

Every file is written atomically; ``--json`` prints the files written.
"""

from __future__ import annotations

import json
from pathlib import Path

from ..atomic import atomic_output, check_output_file
from ..mitsuba import scene_to_mitsuba, write_mitsuba
from ..pbrt import scene_to_pbrt
from ..povray import scene_to_pov
from ..scene import MODELS
from . import COMMAND_HELP
from ._options import SCENE_HELP, SEED, SPP, load_scene_argument, with_lens_option

__all__ = ["add_parser", "run", "FORMATS"]

FORMATS = ("povray", "mitsuba", "pbrt")


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "export", help=COMMAND_HELP["export"],
        description="Write SCENE in another renderer's own format, so that it can be rendered there: POV-Ray SDL, "
                    "Mitsuba 3 XML (meshes in FILE_meshes/ beside it) or pbrt-v4 scene text.")
    p.add_argument("scene", metavar="SCENE.toml", help=SCENE_HELP)
    p.add_argument("--to", required=True, choices=FORMATS, help="the format")
    p.add_argument("-o", "--output", required=True, metavar="FILE")
    p.add_argument("--model", choices=MODELS, help="camera model (default: the scene's)")
    p.add_argument("--lens", metavar="NAME|PATH", help="lens prescription to use")
    p.add_argument("--spp", type=SPP, help="samples per pixel (default: the scene's render.spp)")
    p.add_argument("--seed", type=SEED, help="sampler seed, Mitsuba (at most 2^32 - 1) and pbrt (default: the "
                                             "scene's render.seed)")
    p.add_argument("--json", action="store_true", help="print the files written as JSON")
    p.set_defaults(run=run)


def run(args) -> int:
    output = check_output_file(args.output, option="-o")  # before the export, not after
    scene = with_lens_option(load_scene_argument(args.scene), args.lens)
    if args.to == "povray":
        text = scene_to_pov(scene, model=args.model, spp=args.spp)
        written = [_write_text(output, text)]
    elif args.to == "mitsuba":
        exported = scene_to_mitsuba(scene, model=args.model, spp=args.spp, seed=args.seed,
                                    mesh_prefix=f"{output.stem}_meshes/")
        written = write_mitsuba(exported, output)
    else:
        exported = scene_to_pbrt(scene, model=args.model, spp=args.spp, seed=args.seed,
                                 lens_file=f"{output.stem}.lens.dat")
        written = [_write_text(output.parent / name, text) for name, text in exported.files.items()]
        written.append(_write_text(output, exported.text))
    if args.json:
        print(json.dumps({"format": args.to, "output": str(output), "files": [str(p) for p in written]}))
    return 0


def _write_text(path: Path, text: str) -> Path:
    with atomic_output(path, option="-o") as tmp:
        Path(tmp).write_text(text, encoding="utf-8")
    return path
