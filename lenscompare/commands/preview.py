"""``lenscompare preview IN.exr -o OUT.png``: an sRGB PNG of a linear EXR."""

from __future__ import annotations

from ..errors import InputError
from ..image import read_exr, write_png_preview

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> None:
    p = subparsers.add_parser("preview", help="write an sRGB PNG preview of a linear EXR",
                              description="Encode a linear EXR as an 8-bit sRGB PNG (values above 1 clip).")
    p.add_argument("image", metavar="IN.exr")
    p.add_argument("-o", "--output", required=True, metavar="OUT.png")
    p.add_argument("--exposure", type=float, default=1.0, help="linear scale applied before encoding")
    p.set_defaults(run=run)


def run(args) -> int:
    if not str(args.output).lower().endswith(".png"):
        raise InputError("-o", f"expected a .png file name, got {args.output!r}")
    if not args.exposure > 0:
        raise InputError("--exposure", f"expected a positive number, got {args.exposure}")
    write_png_preview(args.output, read_exr(args.image), exposure=args.exposure)
    return 0
