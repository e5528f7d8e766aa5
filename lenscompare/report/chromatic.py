"""The report's chromatic section: how much colour each scene's lens shows.

Today the section is predictions only: for each report scene (with the lens
the report rendered it through), the planner's ``lateral_color`` and
``longitudinal_color`` (px) and the lens's ``chromatic_focal_shift_mm``, in a
table beside the chromatic teaching figure. No render shows colour yet: the
report renders RGB.

Hook for spectral renders: :func:`chromatic_section` takes ``measured``, a
dict of scene name to measured sizes ({"lateral_color_px": ...,
"longitudinal_color_px": ...}), which the report will fill from spectral
renders of a dot grid and of blur disks through
:func:`lenscompare.metrics.lateral_color` and
:func:`lenscompare.metrics.channel_blur_disks` once the spectral render loop
is merged (``[render] spectral``). Rows without a measurement read None.
"""

from __future__ import annotations

from ..errors import InputError
from ..lenses.paraxial import chromatic_focal_shift_mm
from ..plan import Plan
from ..scene import Scene

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
    note += ("Measured on spectral renders." if measured else
             "Not measured: the report's renders are RGB (spectral renders, [render] spectral, are not "
             "part of the report yet).")
    return {"rows": rows, "figure": figure, "spectral_renders": bool(measured), "note": note}
