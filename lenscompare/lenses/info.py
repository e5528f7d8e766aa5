"""A lens's first-order data as one flat record: what ``lenscompare lens info``
prints and what the ``lens_paraxial`` check compares.

Values are for an object at infinity in n_d light, wide open; axial positions
are mm from the FIRST vertex, positive toward the film (DESIGN.md).
"""

from __future__ import annotations

from ..errors import InputError
from .focus import closest_focus_distance_m
from .glass import CatalogueGlass
from .paraxial import chromatic_focal_shift_mm, paraxial_data
from .prescription import Prescription

__all__ = ["LENS_INFO_FIELDS", "lens_info"]

# (JSON key, label for the table, unit) in the order both outputs list them.
LENS_INFO_FIELDS = (
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
    ("chromatic_focal_shift_mm", "chromatic focal shift (BFL at F minus at C)", "mm"),
    ("closest_focus_m", "closest focus (beyond, from entrance pupil)", "m"),
)


def lens_info(prescription: Prescription) -> dict:
    """First-order data of a lens as a flat dict (the ``--json`` object).

    Keys: ``name``, ``source``, ``sha256``, ``surfaces``, ``stop_surface``
    (1-based row among the surfaces), the keys of
    :class:`~lenscompare.lenses.paraxial.ParaxialData` ending in ``_mm`` and
    ``f_number``, and ``closest_focus_m`` (None when the lens forms no real
    image).  Pupils at infinity read ``inf`` here and ``null`` in JSON.
    ``chromatic_focal_shift_mm`` is 0 for a lens that does not disperse;
    ``glasses`` lists the dispersing media, one dict per surface with
    ``surface`` (1-based), ``line`` and either ``glass`` and ``catalogue`` or
    ``abbe_v_d``.
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
    extra = {"closest_focus_m": closest_m, "chromatic_focal_shift_mm": _focal_shift_or_none(prescription)}
    for key, _, _ in LENS_INFO_FIELDS:
        info[key] = extra[key] if key in extra else getattr(data, key)
    info["glasses"] = [_glass_entry(index, surface) for index, surface in enumerate(prescription.surfaces)
                       if surface.glass is not None]
    return info


def _focal_shift_or_none(prescription: Prescription) -> float | None:
    try:
        return chromatic_focal_shift_mm(prescription)
    except InputError:  # afocal at F or C: no back focal length there
        return None


def _glass_entry(index: int, surface) -> dict:
    glass = surface.glass
    entry = {"surface": index + 1, "line": surface.line}
    if isinstance(glass, CatalogueGlass):
        entry.update(glass=glass.name, catalogue=glass.catalogue)
    else:
        entry.update(abbe_v_d=glass.abbe_v_d)
    return entry
