"""The effect planner: predicted magnitudes against what renders measure, and
the model it picks for scenes built to need (or not need) each effect."""

import json

import pytest

from lenscompare.lenses import load_prescription, paraxial_data
from lenscompare.metrics import find_point_sources, relative_illumination_at
from lenscompare.plan import plan_scene, render_planned
from lenscompare.plan.prediction import compare_predictions
from lenscompare.render import render
from lenscompare.scene import parse_scene

from helpers import camera_scene_text, run_cli, sphere_text


def point_scene(depths_m, *, f_number, focus_m, spread=0.25, resolution=(240, 160), spp=64):
    """Emissive points at the given depths, spread across the frame."""
    objects = ""
    for i, z in enumerate(depths_m):
        x = (i - (len(depths_m) - 1) / 2) / max(1, len(depths_m) - 1) * 2 * spread * z
        objects += sphere_text((x, 0.0, z), 0.0008 * z)
    return parse_scene(camera_scene_text(f_number=f_number, focus_distance=focus_m, resolution=resolution, spp=spp,
                                         objects=objects))


def measured_diameters(image):
    return [s.second_moment_diameter_px for s in find_point_sources(image.pixels)]


def test_far_landscape_stopped_down_plans_pinhole_and_the_thin_lens_adds_nothing_visible():
    scene = point_scene([60.0, 100.0, 200.0], f_number=16.0, focus_m=100.0)
    plan = plan_scene(scene, measure_costs=False)
    assert plan.model == "pinhole" and not plan.needed["defocus"]
    pinhole = measured_diameters(render(scene, model="pinhole", threads=2))
    thin = measured_diameters(render(scene, model="thin", threads=2))
    assert len(pinhole) == len(thin) == 3
    assert max(abs(a - b) for a, b in zip(pinhole, thin)) < plan.tolerance_px


def test_close_up_at_f_1_4_plans_thin_and_the_pinhole_would_miss_the_blur():
    scene = point_scene([0.5, 0.8, 1.6], f_number=1.4, focus_m=0.8)
    plan = plan_scene(scene, measure_costs=False)
    assert plan.model == "thin" and plan.needed["defocus"]
    predicted = plan.effects["defocus"].magnitude
    thin = measured_diameters(render(scene, model="thin", threads=2))
    pinhole = measured_diameters(render(scene, model="pinhole", threads=2))
    # The largest blur disk measured matches the prediction; the pinhole has none of it.
    assert max(thin) == pytest.approx(predicted, rel=0.08)
    assert max(thin) - max(pinhole) > plan.tolerance_px


def test_a_lens_scene_without_an_f_number_renders_the_planned_thin_lens_at_the_lens_s_own():
    """The plan sizes defocus at the lens's own f-number, wide open, when the scene gives none;
    --model auto then renders the thin lens it chose at that f-number (it had stopped with
    "camera.f_number: required for the thin model": session 55, found by planning random lenses)."""
    scene = point_scene([0.5, 0.8, 1.6], f_number=2.0, focus_m=0.8)
    scene = scene.with_camera(lens=load_prescription("dgauss.50mm"), f_number=None)
    plan = plan_scene(scene, tolerance_px=3.0, tolerance_percent=100.0, measure_costs=False)
    assert plan.model == "thin" and plan.needed["defocus"] and not plan.needed["aberrations"]
    image = render_planned(scene, plan=plan, threads=2, progress=False)
    assert image.metadata["camera"]["f_number"] == pytest.approx(paraxial_data(scene.camera.lens).f_number,
                                                                 rel=1e-12)
    predicted = plan.effects["defocus"].magnitude
    assert max(measured_diameters(image)) == pytest.approx(predicted, rel=0.15)


def flat_field(lens, *, focus_m, f_number=None, resolution=(96, 64)):
    text = camera_scene_text(model="lens", focus_distance=focus_m, resolution=resolution, spp=64)
    text = text.replace("focal_length_mm = 50.0\n", "").replace("f_number = 2.8\n", "")
    text = text.replace('model = "lens"', f'model = "lens"\nlens = "{lens}"'
                        + (f"\nf_number = {f_number}" if f_number else ""))
    return parse_scene(text + "\n[background]\ncolor = [1.0, 1.0, 1.0]\n")


def test_fisheye_plans_its_distortion_and_vignetting_and_thin_would_light_the_black_corners():
    scene = flat_field("fisheye.10mm", focus_m=3.0)
    plan = plan_scene(scene, measure_costs=False)
    assert plan.needed["vignetting"] and plan.needed["distortion"]
    assert plan.model in ("composite", "lens") and {"distortion", "vignetting"} <= set(plan.simulated)
    lens = render(scene, model="lens", threads=2).pixels
    auto = render_planned(scene, threads=2).pixels
    thin = render(scene.with_camera(f_number=4.0), model="thin", threads=2).pixels
    assert lens[0, 0].max() == auto[0, 0].max() == 0.0 and thin[0, 0].min() == pytest.approx(1.0)


def test_a_composite_that_cannot_stand_in_for_the_lens_falls_back_to_the_lens_system(monkeypatch):
    # A screen direction cannot look sideways: field angles past MAX_FIELD_DEG are out of
    # the composite's reach. Lowered here so that the fisheye's lit film needs them.
    from lenscompare.lenses import maps

    monkeypatch.setattr(maps, "MAX_FIELD_DEG", 60.0)
    monkeypatch.setattr(maps, "_CACHE", {})
    scene = flat_field("fisheye.10mm", focus_m=3.0)
    plan = plan_scene(scene, measure_costs=False)
    assert plan.model == "lens" and "no composite" in plan.note and "aberrations" not in plan.composite_effects


def test_effects_are_the_unit_distortion_and_vignetting_plan_a_composite_of_just_those():
    scene = flat_field("dgauss.50mm", focus_m=3.0, f_number=8.0)
    plan = plan_scene(scene, measure_costs=False)
    assert plan.model == "composite" and plan.needed["vignetting"] and not plan.needed["defocus"]
    assert set(plan.composite_effects) == {name for name in ("distortion", "vignetting") if plan.needed[name]}
    assert plan.simulated == plan.composite_effects
    # Nothing above tolerance: the pinhole; defocus alone: the thin lens (tested above).
    loose = plan_scene(scene, tolerance_px=1e9, tolerance_percent=100.0, measure_costs=False)
    assert loose.model == "pinhole" and loose.simulated == ()


@pytest.mark.parametrize("lens, focus_m, f_number", [("telephoto.250mm", 20.0, 8.0), ("dgauss.50mm", 3.0, 2.1)])
def test_predicted_corner_falloff_matches_a_rendered_flat_field(lens, focus_m, f_number):
    scene = flat_field(lens, focus_m=focus_m, f_number=f_number, resolution=(120, 80))
    plan = plan_scene(scene, measure_costs=False)
    predicted = plan.effects["vignetting"].magnitude
    # Measured at the corner radius itself, on a film widened by a margin
    # (same lens, film position and pixels): the prediction is for the
    # corner, where falloff is steepest (1.5 px inside it, 1.3 % less).
    (row,) = compare_predictions(scene, plan, spp=256, threads=2, effects=("vignetting",))
    measured = row.measured
    print(f"{lens}: corner falloff predicted {predicted:.2f} %, measured {measured:.2f} %")
    assert measured == pytest.approx(predicted, abs=1.5)
    assert plan.needed["vignetting"] == (predicted > plan.tolerance_percent)


def test_plan_command_json_and_render_auto(tmp_path, write_scene):
    scene = write_scene(camera_scene_text(f_number=1.4, focus_distance=0.8, resolution=(48, 32), spp=2,
                                          objects=sphere_text((0.0, 0.0, 0.5), 0.01)))
    result = run_cli("plan", scene, "--json", "--tolerance-px", "1.0")
    assert result.returncode == 0, result.stderr
    data = json.loads(result.stdout)
    assert data["model"] == "thin" and data["tolerance"]["px"] == 1.0 and data["simulated"] == ["defocus"]
    assert {"model", "effects", "simulated", "tolerance", "predicted_seconds"} <= set(data)
    assert set(data["effects"]) >= {"defocus", "distortion", "vignetting"}
    assert data["effects"]["defocus"]["needed"] and data["effects"]["defocus"]["unit"] == "px"
    assert all({"needed", "magnitude", "unit", "detail"} <= set(e) for e in data["effects"].values())
    out = tmp_path / "auto.exr"
    rendered = run_cli("render", scene, "-o", out, "--model", "auto", "--json")
    assert rendered.returncode == 0, rendered.stderr
    report = json.loads(rendered.stdout)
    assert report["model"] == "thin" and report["plan"]["model"] == "thin"
    bad = run_cli("plan", scene, "--tolerance-px", "-1")
    assert bad.returncode == 2 and "--tolerance-px" in bad.stderr
