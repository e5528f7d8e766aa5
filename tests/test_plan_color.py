"""The planner's colour effects (``lateral_color``, ``longitudinal_color``) and
the lateral-colour map, against rayoptics' real chief rays and paraxial
formulas. The rayoptics models are built from the lens files by
tests/rayoptics_models.py, not by our parser; wavelengths are set there."""

from __future__ import annotations

import dataclasses

import json
import math
from pathlib import Path

import pytest

from lenscompare.cameras import camera_for
from lenscompare.lenses import (chief_ray_heights_at_mm, load_prescription, paraxial_data, stopped_down)
from lenscompare.lenses.chromatic import longitudinal_color_blur_mm
from lenscompare.lenses.glass import C_NM, D_NM, F_NM
from lenscompare.lenses.paraxial import chromatic_focal_shift_mm
from lenscompare.plan import plan_scene
from lenscompare.plan.effects import corner_field_deg, ideal_camera
from lenscompare.scene import parse_scene

from helpers import camera_scene_text, run_cli

DATA = Path(__file__).parent / "data" / "lenses"
SINGLET = DATA / "biconvex_bk7.abbe.dat"   # stop 2 mm in front: lateral colour
TRIPLET = DATA / "cooke_triplet.abbe.dat"


def lens_scene_text(lens, *, f_number=5.6, focus_m=3.0, resolution=(360, 240)):
    text = camera_scene_text(model="lens", f_number=f_number, focus_distance=focus_m, resolution=resolution, spp=4)
    return text.replace("focal_length_mm = 50.0\n", f'lens = "{lens}"\n')


def rayoptics_chief_ray_heights_mm(path, *, field_height_mm, object_to_first_vertex_mm, image_gap_mm, guess_mm):
    """Real chief-ray film heights at F and C traced by rayoptics (its
    refraction, its glass), the object a fixed point, the image plane fixed.
    The chief ray is found here by bisection on its height at rayoptics' stop
    surface (rayoptics' own aiming left 1 mm at the triplet's stop)."""
    import numpy as np
    from rayoptics.raytr import trace
    from rayoptics_models import rayoptics_model
    from scipy.optimize import brentq

    heights = []
    for wavelength in (F_NM, C_NM):
        opm = rayoptics_model(path, wavelength_nm=wavelength)
        sm = opm["seq_model"]
        sm.gaps[0].thi = object_to_first_vertex_mm
        sm.gaps[-1].thi = image_gap_mm
        opm.update_model()
        start = np.array([0.0, field_height_mm, 0.0])

        def ray(y1):  # from the object point toward height y1 on the first vertex plane
            direction = np.array([0.0, y1 - field_height_mm, object_to_first_vertex_mm])
            return trace.trace(sm, start, direction / np.linalg.norm(direction), wavelength).ray

        def at_stop(y1):
            return ray(y1)[sm.stop_surface][0][1]

        y1 = brentq(at_stop, guess_mm - 3.0, guess_mm + 3.0, xtol=1e-12)
        heights.append(float(ray(y1)[-1][0][1]))
    return heights


@pytest.mark.parametrize("path", [SINGLET, TRIPLET])
def test_lateral_color_is_rayoptics_chief_ray_difference_at_the_corner(path):
    pytest.importorskip("rayoptics")
    scene = parse_scene(lens_scene_text(path))
    plan = plan_scene(scene, measure_costs=False)
    system = camera_for(scene, "lens")
    angle = corner_field_deg(scene, ideal_camera(scene))
    lens = scene.camera.lens
    distance_mm = 1000.0 * system.focus_distance_m
    blue, red = rayoptics_chief_ray_heights_mm(
        path, field_height_mm=distance_mm * math.tan(math.radians(angle)),
        object_to_first_vertex_mm=distance_mm - paraxial_data(lens).entrance_pupil_position_mm,
        image_gap_mm=system.film_z_mm - lens.total_track_mm,
        guess_mm=paraxial_data(lens).entrance_pupil_position_mm * math.tan(math.radians(angle)))
    theirs_px = abs(abs(blue) - abs(red)) / system.pixel_pitch_mm
    assert theirs_px > 0.01  # a real difference, not rounding
    assert plan.effects["lateral_color"].magnitude == pytest.approx(theirs_px, rel=0.01)
    ours = chief_ray_heights_at_mm(lens, angle, wavelengths_nm=(F_NM, C_NM), film_z_mm=system.film_z_mm,
                                   focus_distance_m=system.focus_distance_m)
    assert abs(ours[0]) == pytest.approx(abs(blue), abs=1e-6) and abs(ours[1]) == pytest.approx(abs(red), abs=1e-6)


@pytest.mark.parametrize("path", [SINGLET, TRIPLET])
def test_longitudinal_color_far_away_is_the_focal_shift_over_the_f_number(path):
    """Paraxial truth for a distant object: the F cone (f-number N_F = f_F / D,
    about N) crosses the C focus, |BFL_F - BFL_C| from its own, in a disk of |shift| / N_F."""
    scene = parse_scene(lens_scene_text(path, f_number=8.0, focus_m=1e6))
    plan = plan_scene(scene, measure_costs=False)
    pitch = 36.0 / 360
    blue = paraxial_data(stopped_down(scene.camera.lens, 8.0).at_wavelength(F_NM))
    assert blue.f_number == pytest.approx(8.0, rel=0.03)
    expected = abs(chromatic_focal_shift_mm(scene.camera.lens)) / blue.f_number / pitch
    assert expected > 0.05
    assert plan.effects["longitudinal_color"].magnitude == pytest.approx(expected, rel=0.01)
    assert plan.needed["longitudinal_color"] == (expected > plan.tolerance_px)


def test_longitudinal_color_up_close_agrees_with_rayoptics_paraxial_rays():
    """At 0.6 m: rayoptics' paraxial marginal ray at F (entrance pupil of the
    stopped-down lens) crossing its own paraxial C image plane."""
    pytest.importorskip("rayoptics")
    from rayoptics.raytr.opticalspec import PupilSpec
    from rayoptics_models import rayoptics_model

    lens = stopped_down(load_prescription(TRIPLET), 8.0)
    pupil = paraxial_data(lens)
    object_mm = 600.0 - pupil.entrance_pupil_position_mm
    rays = {}
    for wavelength in (F_NM, C_NM):
        opm = rayoptics_model(TRIPLET, wavelength_nm=wavelength)
        osp = opm["optical_spec"]
        opm["seq_model"].gaps[0].thi = object_mm
        osp["pupil"] = PupilSpec(osp, key=["object", "epd"], value=pupil.entrance_pupil_diameter_mm)
        opm.update_model()
        ax_ray = opm["analysis_results"]["parax_data"].ax_ray
        rays[wavelength] = ax_ray[-2][0], ax_ray[-2][1]  # height and slope behind the last surface
    red_image = -rays[C_NM][0] / rays[C_NM][1]
    theirs = 2.0 * abs(rays[F_NM][0] + rays[F_NM][1] * red_image)
    assert longitudinal_color_blur_mm(lens, focus_distance_m=0.6) == pytest.approx(theirs, rel=0.01)


def test_a_lens_without_dispersion_has_no_colour():
    plan = plan_scene(parse_scene(lens_scene_text("dgauss.50mm", f_number=2.8)), measure_costs=False)
    for name in ("lateral_color", "longitudinal_color"):
        assert plan.effects[name].magnitude == 0.0 and not plan.needed[name]
        assert "does not disperse" in plan.effects[name].detail
    thin = plan_scene(parse_scene(camera_scene_text()), measure_costs=False)
    assert thin.effects["lateral_color"].magnitude == 0.0 and "no prescription" in thin.effects["lateral_color"].detail


def test_colour_is_needed_only_above_tolerance_and_an_rgb_render_leaves_it_out(tmp_path):
    path = tmp_path / "singlet.toml"
    path.write_text(lens_scene_text(SINGLET, f_number=5.6))
    size = plan_scene(parse_scene(path.read_text()), measure_costs=False).effects["longitudinal_color"].magnitude
    assert size > 1.0
    out = {}
    for tolerance in (0.5 * size, 2.0 * size):
        result = run_cli("plan", str(path), "--json", "--no-costs", "--tolerance-px", str(tolerance))
        assert result.returncode == 0, result.stderr
        out[tolerance] = json.loads(result.stdout)
    above, below = out[0.5 * size], out[2.0 * size]
    assert above["effects"]["longitudinal_color"]["needed"] and not below["effects"]["longitudinal_color"]["needed"]
    assert above["effects"]["longitudinal_color"]["magnitude"] == pytest.approx(size)
    # No RGB model shows colour: it is named in the note, never in `simulated`, and does not pick the model.
    assert "longitudinal_color" in above["note"] and "spectral" in above["note"]
    assert "longitudinal_color" not in above["simulated"] + below["simulated"]
    assert "note" not in below or "longitudinal_color" not in below["note"]


def test_the_lateral_colour_map_gives_the_planner_size_at_the_corner():
    """The composite's per-wavelength distortion table, read backward at the
    corner field, has the planner's F - C shift (interpolated over 65 angles)."""
    scene = parse_scene(lens_scene_text(SINGLET, f_number=5.6))
    plan = plan_scene(scene, measure_costs=False)
    composite = camera_for(scene, "composite", effects=("distortion",))
    table = composite.lateral_color_map()
    wavelengths = list(table.wavelengths_nm)
    assert wavelengths == sorted(wavelengths) and {F_NM, D_NM, C_NM} <= set(wavelengths)
    tangent = math.tan(math.radians(corner_field_deg(scene, ideal_camera(scene))))
    shift_px = abs(table.lateral_color_mm(tangent)) / composite.pixel_pitch_mm
    assert shift_px == pytest.approx(plan.effects["lateral_color"].magnitude, rel=0.01)
    # Its d row is the distortion map the composite already renders with.
    entries = len(composite.maps.field_tangent)
    d_row = table.field_tangent[list(table.wavelengths_nm).index(D_NM)]
    assert d_row[:entries] == pytest.approx(composite.maps.field_tangent, rel=2e-4)
    wavelengths, scale, step = composite.lateral_color_arrays()
    assert scale.shape == (len(wavelengths), len(d_row)) and len(d_row) > entries and scale.flags.c_contiguous
    assert step == composite.maps.radius_step_mm and scale[:, 0] == pytest.approx(1.0)


def test_spectral_renders_pick_the_model_that_shows_colour():
    """With ``[render] spectral = true``: longitudinal colour alone needs the
    thin lens derived from the prescription; lateral colour the lens system.
    A 6 x 4 mm film at f/11: the singlet's colour (8.8 px) dwarfs its
    aberrations (2.1 px)."""
    text = lens_scene_text(SINGLET, f_number=11.0).replace("film_mm = [36.0, 24.0]", "film_mm = [6.0, 4.0]")
    scene = parse_scene(text)
    rgb = plan_scene(scene, measure_costs=False, tolerance_px=3.0)
    assert [name for name, needed in rgb.needed.items() if needed] == ["longitudinal_color"]
    assert rgb.model == "pinhole" and "longitudinal_color" not in rgb.simulated
    scene = dataclasses.replace(scene, render=dataclasses.replace(scene.render, spectral=True))
    spectral = plan_scene(scene, measure_costs=False, tolerance_px=3.0)
    assert spectral.model == "thin" and "longitudinal_color" in spectral.simulated and "spectral" not in spectral.note
    lateral = plan_scene(scene, measure_costs=False, tolerance_px=0.1, tolerance_percent=100.0)
    assert lateral.needed["lateral_color"] and lateral.model == "lens" and "lateral_color" in lateral.simulated
