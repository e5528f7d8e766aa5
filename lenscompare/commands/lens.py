"""``lenscompare lens info LENS [--json]``: first-order data of a lens system;
``lenscompare lens import FILE.zmx -o OUT.dat``: a Zemax lens as a lens file.

LENS is a shipped name (``dgauss.50mm``) or the path of a pbrt lens file.
Values are for an object at infinity in n_d light, wide open; axial positions
are mm from the FIRST vertex, positive toward the film (DESIGN.md).
"""

from __future__ import annotations

import json
import math

from ..atomic import atomic_output, check_output_file
from ..lenses import load_prescription, shipped_lens_names
from ..lenses.info import LENS_INFO_FIELDS, lens_info
from ..lenses.zemax import zemax_to_lens_text
from . import COMMAND_HELP

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> None:
    """Register ``lens`` and its ``info`` sub-command."""
    parser = subparsers.add_parser(
        "lens", help=COMMAND_HELP["lens"],
        description="Inspect lens prescriptions (pbrt format).")
    commands = parser.add_subparsers(dest="lens_command", metavar="{info,import}", required=True)
    info = commands.add_parser(
        "info", help="first-order data of a lens",
        description="First-order (paraxial) data of a lens, object at infinity, n_d light. "
        "Axial positions are mm from the first vertex, positive toward the film. "
        "Shipped lenses: " + ", ".join(shipped_lens_names()) + ".")
    info.add_argument("lens", metavar="LENS", help="shipped lens name or path of a lens file")
    info.add_argument("--json", action="store_true", help="print one JSON object")
    info.set_defaults(run=run)
    convert = commands.add_parser(
        "import", help="convert a Zemax OpticStudio .zmx lens to a lens file",
        description="Convert a sequential Zemax OpticStudio lens (.zmx) to a lens file, glass names "
        "kept. Mirrors, aspheres and conics, tilts and coordinate breaks, gradient index and other "
        "non-standard surfaces are refused, naming the surface.")
    convert.add_argument("zmx", metavar="FILE.zmx", help="the Zemax file")
    convert.add_argument("-o", "--output", required=True, metavar="OUT.dat", help="lens file to write")
    convert.set_defaults(run=run_import)


def run(args) -> int:
    """Print the lens's first-order data as a table or as JSON; return 0."""
    info = lens_info(load_prescription(args.lens))
    if args.json:
        print(json.dumps(_json_safe(info), allow_nan=False))
    else:
        print(_table(info))
    return 0


def run_import(args) -> int:
    """Write the Zemax file as a lens file (atomically); return 0."""
    output = check_output_file(args.output)
    text = zemax_to_lens_text(args.zmx)
    with atomic_output(output, final=True) as tmp:
        tmp.write_text(text, encoding="utf-8")
    print(f"wrote {output}")
    return 0


def _json_safe(info: dict) -> dict:
    """Infinite values become null: JSON has no infinity."""
    return {key: None if isinstance(value, float) and not math.isfinite(value) else value
            for key, value in info.items()}


def _number(value: float, unit: str) -> str:
    """Four decimals for ordinary lengths; 4 significant digits for metres and
    for values too large or small for a fixed column (a nearly powerless lens)."""
    if unit == "m" or not math.isfinite(value) or (value != 0 and not 1e-3 <= abs(value) < 1e7):
        return f"{value:.4g}"
    return f"{value:.4f}"


def _table(info: dict) -> str:
    """A small readable table."""
    lines = [f"{info['name']}  ({info['surfaces']} surfaces, stop is surface "
             f"{info['stop_surface']}; sha256 {info['sha256'][:12]}...)",
             "positions in mm from the first vertex, positive toward the film"]
    width = max(len(label) for _, label, _ in LENS_INFO_FIELDS)
    for key, label, unit in LENS_INFO_FIELDS:
        value = info[key]
        shown = "n/a" if value is None else _number(value, unit)
        lines.append(f"  {label:<{width}}  {shown:>10} {unit}".rstrip())
    if info["glasses"]:
        lines.append("glass (medium after each surface): " + ", ".join(
            f"{g['surface']} {g['glass']} ({g['catalogue']})" if "glass" in g else f"{g['surface']} V_d {g['abbe_v_d']:g}"
            for g in info["glasses"]))
    return "\n".join(lines)
