"""``lenscompare preview IN.exr -o OUT.png``: an sRGB PNG of a linear EXR."""

from __future__ import annotations

from ..image import read_exr, write_png_preview
from . import COMMAND_HELP
from ._options import POSITIVE, check_output_suffix

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> None:
    p = subparsers.add_parser("preview", help=COMMAND_HELP["preview"],
                              description="Encode a linear EXR as an 8-bit sRGB PNG (values above 1 clip).")
    p.add_argument("image", metavar="IN.exr")
    p.add_argument("-o", "--output", required=True, metavar="OUT.png")
    p.add_argument("--exposure", type=POSITIVE, default=1.0, help="linear scale applied before encoding")
    p.set_defaults(run=run)


def run(args) -> int:
    output = check_output_suffix(args.output, ".png")
    write_png_preview(output, read_exr(args.image), exposure=args.exposure, final=True)
    return 0
