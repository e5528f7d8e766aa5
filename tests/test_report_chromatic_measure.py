"""Lateral colour measured on the report's spectral dot chart
(lenscompare/report/chromatic_measure.py) against the chief-ray prediction,
and no render for a lens that does not disperse."""

from __future__ import annotations

import json
import math
from importlib import resources

import numpy as np
import pytest

from lenscompare.plan import plan_scene
from lenscompare.report import chromatic_measure
from lenscompare.report.chromatic import chromatic_section
from lenscompare.report.chromatic_measure import measure_lateral_color
from lenscompare.scene import load_scene
from lenscompare.reference_scenes import scenes_dir

from test_report_chromatic import lens_scene


@pytest.fixture(scope="module")
def landscape():
    """The shipped landscape lens (N-BK7 meniscus behind its stop) at f/32, 5 m, 36 x 24 mm."""
    scene = load_scene(scenes_dir() / "effects" / "landscape_color.toml")
    return scene, measure_lateral_color(scene, threads=2)


def test_rendered_lateral_colour_at_two_fields_is_within_10_percent_of_the_chief_ray(landscape):
    """The issue's goal: F minus C image height of the rendered dots at 0.7 of
    the corner field and at the corner, within 10 % of the chief rays traced at
    F and C (measured with seed 15: +2.7 % and +0.6 %; over seeds 1-3 the
    mid field spreads -7 to +1 %, the corner -2 to 0 %)."""
    scene, result = landscape
    assert len(result.field_deg) == 2 and result.field_deg[0] < result.field_deg[1]
    for measured, predicted in zip(result.measured_px, result.predicted_px):
        assert abs(predicted) > 0.3  # a real shift, a sizeable part of a pixel
        assert measured == pytest.approx(predicted, rel=0.10)
    # The corner prediction is the planner's own, the table's predicted column.
    plan = plan_scene(scene, measure_costs=False)
    assert abs(result.predicted_px[-1]) == pytest.approx(plan.effects["lateral_color"].magnitude, rel=1e-12)
    assert result.corner_px == abs(result.measured_px[-1])


def test_the_measurement_is_deterministic_whatever_the_thread_count(landscape):
    scene, result = landscape
    again = measure_lateral_color(scene, threads=1)
    assert again.measured_px == result.measured_px


def test_a_lens_that_does_not_disperse_gets_no_measurement_and_no_render(monkeypatch):
    def no_render(*args, **kwargs):
        raise AssertionError("a render for a lens that does not disperse")

    monkeypatch.setattr(chromatic_measure, "render", no_render)
    assert measure_lateral_color(lens_scene("dgauss.50mm")) is None


def test_the_measured_section_follows_the_schema(landscape):
    jsonschema = pytest.importorskip("jsonschema")
    scene, result = landscape
    plans = {"landscape": (scene, plan_scene(scene, measure_costs=False)),
             "dgauss": (lens_scene("dgauss.50mm"), plan_scene(lens_scene("dgauss.50mm"), measure_costs=False))}
    measured = {"landscape": {"lateral_color_px": result.corner_px, "longitudinal_color_px": None,
                              "fields_deg": list(result.field_deg), "measured_px": list(result.measured_px),
                              "predicted_px": list(result.predicted_px)}}
    section = json.loads(json.dumps(chromatic_section(plans, measured=measured)))
    schema = json.loads(resources.files("lenscompare.report").joinpath("results.schema.json").read_text())
    assert list(jsonschema.Draft202012Validator(schema["properties"]["chromatic"]).iter_errors(section)) == []
    rows = {row["scene"]: row for row in section["rows"]}
    assert section["spectral_renders"] and math.isfinite(rows["landscape"]["measured_lateral_color_px"])
    assert rows["dgauss"]["measured_lateral_color_px"] is None
    assert "486.13" in section["note"] and "landscape: F - C measured" in section["note"]


def test_the_rendered_f_disk_at_the_c_focus_is_the_real_ray_spot(landscape):
    """Longitudinal colour: the rendered F-line disk at the C line's paraxial
    focus against the same rays traced in Python (point_source_spot_mm at F,
    second moment: a uniform disk reads its diameter), within 3 % (measured
    0.1 %). The paraxial prediction (the planner's) is 11 % smaller."""
    from lenscompare.cameras import camera_for
    from lenscompare.lenses.analysis import point_source_spot_mm
    from lenscompare.lenses.chromatic import axial_image_z_mm
    from lenscompare.lenses.glass import C_NM, F_NM
    from lenscompare.plan.effects import ideal_camera

    scene, _ = landscape
    measured_px, predicted_px = chromatic_measure.measure_longitudinal_color(scene, threads=2)
    system = camera_for(scene, "lens")
    c_focus_mm = axial_image_z_mm(scene.camera.lens, wavelength_nm=C_NM, focus_distance_m=system.focus_distance_m)
    on_film, weight = point_source_spot_mm(system.prescription.at_wavelength(F_NM), height_mm=0.0,
                                           distance_mm=system.focus_distance_mm, film_z_mm=c_focus_mm)
    variance_mm2 = (weight * (on_film[:, 0] - np.average(on_film[:, 0], weights=weight)) ** 2).sum() / weight.sum()
    traced_px = 4.0 * math.sqrt(variance_mm2) / ideal_camera(scene).pixel_pitch_mm
    assert measured_px == pytest.approx(traced_px, rel=0.03)
    plan = plan_scene(scene, measure_costs=False)
    assert predicted_px == pytest.approx(plan.effects["longitudinal_color"].magnitude, rel=1e-12)
    assert predicted_px < measured_px < 1.2 * predicted_px


def test_a_lens_that_does_not_disperse_gets_no_disk_render(monkeypatch):
    def no_render(*args, **kwargs):
        raise AssertionError("a render for a lens that does not disperse")

    monkeypatch.setattr(chromatic_measure, "render", no_render)
    assert chromatic_measure.measure_longitudinal_color(lens_scene("dgauss.50mm")) is None
