"""The report's chromatic section: how much colour each scene's lens shows.

For each report scene (with the lens the report rendered it through): the
planner's ``lateral_color`` and ``longitudinal_color`` (px) and the lens's
``chromatic_focal_shift_mm``, in a table beside the chromatic teaching figure.

For each scene whose lens disperses, the report also measures both sizes on
spectral renders (:mod:`lenscompare.report.chromatic_measure`): lateral
colour on a chart of F-line and C-line dots through the scene's lens system
(:func:`lenscompare.metrics.lateral_color`), longitudinal colour on one
F-line blur disk at the C focus (:func:`lenscompare.metrics.measure_blur_disk`).
They come in as ``measured``, a dict of scene name to measured sizes
({"lateral_color_px": ..., "longitudinal_color_px": ...}, optionally
"fields_deg", "measured_px" and "predicted_px" per field). Rows without a
measurement read None.
"""

from __future__ import annotations

from ..errors import InputError
from ..lenses.paraxial import chromatic_focal_shift_mm
from ..plan import Plan
from ..scene import Scene
from .chromatic_measure import DISK_SPP, SEED, SPP

__all__ = ["chromatic_section", "CHROMATIC_COLUMNS"]

CHROMATIC_COLUMNS = ("scene", "lens", "disperses", "chromatic_focal_shift_mm", "lateral_color_px",
                     "longitudinal_color_px", "lateral_color_needed", "longitudinal_color_needed",
                     "measured_lateral_color_px", "measured_longitudinal_color_px")
"""The table's columns, in order (each row is a dict with these keys)."""


def _focal_shift_mm(scene: Scene) -> float | None:
    lens = scene.camera.lens
    if lens is None:
        return None
    try:
        return chromatic_focal_shift_mm(lens)
    except InputError:  # afocal at F or C
        return None


def chromatic_section(plans: dict[str, tuple[Scene, Plan | dict]], *, figure: str | None = None,
                      measured: dict[str, dict] | None = None) -> dict:
    """The chromatic section's data.

    Parameters
    ----------
    plans : dict of str to (Scene, Plan or dict)
        Per scene name: the scene as rendered and its plan
        (:class:`lenscompare.plan.Plan`, or its ``to_json()``).
    figure : str, optional
        Path of the chromatic teaching figure, relative to the report.
    measured : dict of str to dict, optional
        Per scene name, sizes measured on spectral renders
        (``lateral_color_px``, ``longitudinal_color_px``); see the module notes.

    Returns
    -------
    dict
        ``rows`` (one dict per scene, keys :data:`CHROMATIC_COLUMNS`),
        ``figure``, ``spectral_renders`` (False until measurements are given)
        and ``note``.
    """
    measured = measured or {}
    rows = []
    for name, (scene, plan) in plans.items():
        data = plan.to_json() if isinstance(plan, Plan) else plan
        effects = data["effects"]
        lens = scene.camera.lens
        seen = measured.get(name, {})
        rows.append({
            "scene": name,
            "lens": None if lens is None else lens.name,
            "disperses": bool(lens is not None and lens.disperses),
            "chromatic_focal_shift_mm": _focal_shift_mm(scene),
            "lateral_color_px": effects["lateral_color"]["magnitude"],
            "longitudinal_color_px": effects["longitudinal_color"]["magnitude"],
            "lateral_color_needed": effects["lateral_color"]["needed"],
            "longitudinal_color_needed": effects["longitudinal_color"]["needed"],
            "measured_lateral_color_px": seen.get("lateral_color_px"),
            "measured_longitudinal_color_px": seen.get("longitudinal_color_px"),
        })
    dispersing = [row["lens"] for row in rows if row["disperses"]]
    note = ("Predicted from the scene alone (lenscompare plan): lateral colour is the F - C chief-ray height "
            "difference at the film corner, longitudinal colour the F blur disk at the C focus. ")
    note += ("" if dispersing else "None of the report's lenses disperses (no Abbe number or glass in the lens "
             "file's 5th column), so every size is 0; run the report with --lens on a lens that does. ")
    if measured:
        note += (f"Measured lateral colour: one spectral render per lens camera (the lens system, {SPP} spp, seed {SEED}) of "
                 "white dots emitting only the F line (486.13 nm) on one side and only the C line (656.27 nm) "
                 "on the other, on the plane of focus along the film diagonals; the C half turned 180 degrees "
                 "onto the F half and the F minus C radial centroid shift measured with "
                 "lenscompare.metrics.lateral_color, at the corner field (the column) and at 0.7 of it. ")
        note += " ".join(_field_text(name, seen) for name, seen in measured.items() if seen.get("fields_deg"))
        note += (" Measured longitudinal colour: one F-line dot on the axis rendered through the lens system "
                 f"with the film at the C line's paraxial focus ({DISK_SPP} spp), its blur disk's second-moment "
                 "diameter (lenscompare.metrics.measure_blur_disk); real rays, so it exceeds the paraxial "
                 "prediction where the F light's spherical aberration adds to the defocus."
                 if any(seen.get("longitudinal_color_px") is not None for seen in measured.values())
                 else " Longitudinal colour is not measured.")
    else:
        note += ("Not measured: no lens disperses, or the report's renders are RGB and no spectral chart was "
                 "rendered.")
    return {"rows": rows, "figure": figure, "spectral_renders": bool(measured), "note": note}


def _field_text(name: str, seen: dict) -> str:
    """'scene: measured / predicted px at each field' for the note."""
    pairs = ", ".join(f"{m:+.3g} / {p:+.3g} px at {f:.3g} deg"
                      for f, m, p in zip(seen["fields_deg"], seen["measured_px"], seen["predicted_px"]))
    return f"{name}: F - C measured / predicted {pairs}."
