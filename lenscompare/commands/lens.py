"""``lenscompare lens info LENS [--json]``: first-order data of a lens system.

LENS is a shipped name (``dgauss.50mm``) or the path of a pbrt lens file.
Values are for an object at infinity in n_d light, wide open; axial positions
are mm from the FIRST vertex, positive toward the film (DESIGN.md).
"""

from __future__ import annotations

import json
import math

from ..errors import InputError
from ..lenses.focus import closest_focus_distance_m
from ..lenses.paraxial import paraxial_data
from ..lenses.prescription import Prescription, load_prescription, shipped_lens_names

__all__ = ["add_parser", "run", "lens_info"]

# (JSON key, label for the table, unit) in the order both outputs list them.
_FIELDS = (
    ("effective_focal_length_mm", "effective focal length", "mm"),
    ("back_focal_length_mm", "back focal length (last vertex to F')", "mm"),
    ("front_focal_length_mm", "front focal length (F to first vertex)", "mm"),
    ("front_focal_point_mm", "front focal point F", "mm"),
    ("rear_focal_point_mm", "rear focal point F'", "mm"),
    ("front_principal_plane_mm", "front principal plane H", "mm"),
    ("rear_principal_plane_mm", "rear principal plane H'", "mm"),
    ("entrance_pupil_position_mm", "entrance pupil position", "mm"),
    ("entrance_pupil_diameter_mm", "entrance pupil diameter", "mm"),
    ("exit_pupil_position_mm", "exit pupil position", "mm"),
    ("exit_pupil_diameter_mm", "exit pupil diameter", "mm"),
    ("f_number", "paraxial f-number", ""),
    ("total_track_mm", "total track (first to last vertex)", "mm"),
    ("closest_focus_m", "closest focus (beyond, from entrance pupil)", "m"),
)


def add_parser(subparsers) -> None:
    """Register ``lens`` and its ``info`` sub-command."""
    parser = subparsers.add_parser(
        "lens", help="inspect lens prescriptions",
        description="Inspect lens prescriptions (pbrt format).")
    commands = parser.add_subparsers(dest="lens_command", metavar="info", required=True)
    info = commands.add_parser(
        "info", help="first-order data of a lens",
        description="First-order (paraxial) data of a lens, object at infinity, n_d light. "
        "Axial positions are mm from the first vertex, positive toward the film. "
        "Shipped lenses: " + ", ".join(shipped_lens_names()) + ".")
    info.add_argument("lens", metavar="LENS", help="shipped lens name or path of a lens file")
    info.add_argument("--json", action="store_true", help="print one JSON object")
    info.set_defaults(run=run)


def run(args) -> int:
    """Print the lens's first-order data as a table or as JSON; return 0."""
    info = lens_info(load_prescription(args.lens))
    if args.json:
        print(json.dumps(_json_safe(info), allow_nan=False))
    else:
        print(_table(info))
    return 0


def lens_info(prescription: Prescription) -> dict:
    """First-order data of a lens as a flat dict (the ``--json`` object).

    Keys: ``name``, ``source``, ``sha256``, ``surfaces``, ``stop_surface``
    (1-based row among the surfaces), the keys of
    :class:`~lenscompare.lenses.paraxial.ParaxialData` ending in ``_mm`` and
    ``f_number``, and ``closest_focus_m`` (None when the lens forms no real
    image).  Pupils at infinity read ``inf`` here and ``null`` in JSON.
    """
    data = paraxial_data(prescription)
    try:
        closest_m = closest_focus_distance_m(prescription)
    except InputError:  # a lens that forms no real image still has first-order data
        closest_m = None
    info = {
        "name": prescription.name,
        "source": prescription.source,
        "sha256": prescription.sha256,
        "surfaces": len(prescription.surfaces),
        "stop_surface": data.stop_index + 1,
    }
    for key, _, _ in _FIELDS:
        info[key] = closest_m if key == "closest_focus_m" else getattr(data, key)
    return info


def _json_safe(info: dict) -> dict:
    """Infinite values become null: JSON has no infinity."""
    return {key: None if isinstance(value, float) and not math.isfinite(value) else value
            for key, value in info.items()}


def _table(info: dict) -> str:
    """A small readable table."""
    lines = [f"{info['name']}  ({info['surfaces']} surfaces, stop is surface "
             f"{info['stop_surface']}; sha256 {info['sha256'][:12]}...)",
             "positions in mm from the first vertex, positive toward the film"]
    width = max(len(label) for _, label, _ in _FIELDS)
    for key, label, unit in _FIELDS:
        value = info[key]
        shown = "n/a" if value is None else f"{value:.4f}" if unit != "m" else f"{value:.4g}"
        lines.append(f"  {label:<{width}}  {shown:>10} {unit}".rstrip())
    return "\n".join(lines)
