"""``lenscompare figures -o DIR``: the teaching figures (paper Figs. 1-4) as PNG and SVG.

Writes ``thin_lens``, ``thick_lens``, ``lens_system``, ``aperture``, ``chromatic`` and ``motion`` (``.png``
and ``.svg``) into DIR; see :func:`lenscompare.figures.write_teaching_figures`.
"""

from __future__ import annotations

import json

from ..figures import write_teaching_figures
from ..limits import MAX_F_NUMBER, MAX_FOCAL_LENGTH_MM, MAX_LENGTH_M, MIN_F_NUMBER, MIN_FOCAL_LENGTH_MM
from . import COMMAND_HELP
from ._options import number_option

__all__ = ["add_parser", "run"]


# The limits of a scene's camera (lenscompare.limits) hold for the drawings too.
_FOCAL_LENGTH = number_option(minimum=MIN_FOCAL_LENGTH_MM, maximum=MAX_FOCAL_LENGTH_MM)
_F_NUMBER = number_option(minimum=MIN_F_NUMBER, maximum=MAX_F_NUMBER)
_DISTANCE = number_option(maximum=MAX_LENGTH_M)


def add_parser(subparsers) -> None:
    """Register ``figures``."""
    p = subparsers.add_parser(
        "figures", help=COMMAND_HELP["figures"],
        description="Draw the teaching figures of the paper (Figs. 1-4) from lenscompare's own "
        "optics code: the thin lens with real numbers (eqs. 1-10), the thick-lens model of LENS "
        "(H, H', F, F' against traced rays), and LENS in cross-section with traced bundles, its "
        "exit pupil and the film; and the aperture: defocus against diffraction over the f-number (the best "
        "aperture), bokeh and diffraction stars of 5, 6, 7 and 9 blades; chromatic aberration: ray "
        "fans at F, d and C through a dispersive lens and its focal shift against wavelength; and motion: "
        "a moving point's streak with and without defocus, and one pixel's samples in lens x time (sobol "
        "against padding). Writes thin_lens, thick_lens, lens_system, aperture, chromatic and motion as "
        ".png and .svg "
        "into DIR (created if missing).")
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="folder for the figures")
    p.add_argument("--lens", default="dgauss.50mm", metavar="NAME|PATH",
                   help="lens for the thick-lens and lens-system figures (default: dgauss.50mm)")
    p.add_argument("--chromatic-lens", metavar="NAME|PATH",
                   help="dispersive lens for the chromatic figure (default: --lens when it disperses, "
                   "else an N-BK7 singlet)")
    p.add_argument("--focal-length-mm", type=_FOCAL_LENGTH, default=50.0, metavar="F",
                   help="thin-lens focal length, mm (default: 50)")
    p.add_argument("--f-number", type=_F_NUMBER, default=2.0, metavar="N",
                   help="thin-lens f-number (default: 2)")
    p.add_argument("--focus-distance", type=_DISTANCE, default=2.0, metavar="M",
                   help="plane of focus, m, for the thin lens and the lens system (default: 2)")
    p.add_argument("--object-distances", type=_DISTANCE, nargs="+", default=[1.0, 5.0],
                   metavar="M", help="one to three object points for the thin-lens figure, m "
                   "(default: 1 5)")
    p.add_argument("--no-svg", action="store_true", help="write PNG only")
    p.add_argument("--json", action="store_true",
                   help="print one JSON object: {\"figures\": {name: png path}}")
    p.set_defaults(run=run)


def run(args) -> int:
    """Write the figures; print the PNG paths (or JSON); return 0."""
    written = write_teaching_figures(
        args.output, lens=args.lens, focal_length_mm=args.focal_length_mm,
        f_number=args.f_number, focus_distance_m=args.focus_distance,
        object_distances_m=tuple(args.object_distances), chromatic_lens=args.chromatic_lens,
        svg=not args.no_svg)
    if args.json:
        print(json.dumps({"figures": {name: str(path) for name, path in written.items()}}))
    else:
        for path in written.values():
            print(path)
    return 0
