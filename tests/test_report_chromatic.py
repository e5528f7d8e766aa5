"""The report's chromatic section: the planner's colour sizes per scene in a
table, the teaching figure, and the hook for spectral measurements."""

from __future__ import annotations

import json
from importlib import resources
from pathlib import Path

import pytest

from lenscompare.lenses.paraxial import chromatic_focal_shift_mm
from lenscompare.plan import plan_scene
from lenscompare.report.chromatic import CHROMATIC_COLUMNS, chromatic_section
from lenscompare.report.html import chromatic_body
from lenscompare.scene import parse_scene

from helpers import camera_scene_text

DATA = Path(__file__).parent / "data" / "lenses"


def lens_scene(lens, f_number=5.6):
    text = camera_scene_text(model="lens", f_number=f_number, focus_distance=3.0, spp=4)
    return parse_scene(text.replace("focal_length_mm = 50.0\n", f'lens = "{lens}"\n'))


@pytest.fixture(scope="module")
def plans():
    scenes = {"singlet": lens_scene(DATA / "biconvex_bk7.abbe.dat"), "dgauss": lens_scene("dgauss.50mm")}
    return {name: (scene, plan_scene(scene, measure_costs=False)) for name, scene in scenes.items()}


def test_rows_hold_the_planner_sizes_and_the_focal_shift(plans):
    section = chromatic_section(plans, figure="figures/chromatic.png")
    rows = {row["scene"]: row for row in section["rows"]}
    assert all(tuple(row) == CHROMATIC_COLUMNS for row in rows.values())
    scene, plan = plans["singlet"]
    assert rows["singlet"]["lateral_color_px"] == plan.effects["lateral_color"].magnitude > 0
    assert rows["singlet"]["longitudinal_color_px"] == plan.effects["longitudinal_color"].magnitude > 1
    assert rows["singlet"]["longitudinal_color_needed"] and rows["singlet"]["disperses"]
    assert rows["singlet"]["chromatic_focal_shift_mm"] == chromatic_focal_shift_mm(scene.camera.lens) < 0
    assert rows["dgauss"]["lateral_color_px"] == rows["dgauss"]["longitudinal_color_px"] == 0.0
    assert rows["dgauss"]["chromatic_focal_shift_mm"] == 0.0 and not rows["dgauss"]["disperses"]
    # Without spectral renders nothing is measured, and the note says so.
    assert not section["spectral_renders"] and rows["singlet"]["measured_lateral_color_px"] is None
    assert "RGB" in section["note"]
    # The JSON plan (as the report stores it) gives the same rows.
    as_json = chromatic_section({n: (s, p.to_json()) for n, (s, p) in plans.items()})
    assert as_json["rows"] == section["rows"]


def test_only_non_dispersive_lenses_are_said_to_show_nothing(plans):
    section = chromatic_section({"dgauss": plans["dgauss"]})
    assert "None of the report's lenses disperses" in section["note"]
    assert "None of the report's lenses" not in chromatic_section(plans)["note"]


def test_measurements_from_spectral_renders_fill_their_columns(plans):
    section = chromatic_section(plans, measured={"singlet": {"lateral_color_px": 0.2, "longitudinal_color_px": 2.5}})
    rows = {row["scene"]: row for row in section["rows"]}
    assert section["spectral_renders"] and rows["singlet"]["measured_longitudinal_color_px"] == 2.5
    assert rows["dgauss"]["measured_lateral_color_px"] is None


def test_the_section_follows_the_schema_and_renders_as_a_table(plans):
    jsonschema = pytest.importorskip("jsonschema")
    schema = json.loads(resources.files("lenscompare.report").joinpath("results.schema.json").read_text())
    section = json.loads(json.dumps(chromatic_section(plans, figure="figures/chromatic.png")))
    errors = list(jsonschema.Draft202012Validator(schema["properties"]["chromatic"]).iter_errors(section))
    assert errors == []
    page = chromatic_body(section)
    assert page.count("<tr>") == 3 and "figures/chromatic.png" in page and "biconvex_bk7.abbe" in page
