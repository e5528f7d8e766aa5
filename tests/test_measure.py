"""The measurements the report and the checks make (lenscompare.measure),
against independent expectations: real-ray traces of the same prescription,
equation 5, and the POV-Ray agreement the README quotes."""

from __future__ import annotations

import numpy as np
import pytest

from lenscompare.experiment import ExperimentSettings, Run, prepare_scene
from lenscompare.lenses import chief_ray_distortion_percent
from lenscompare.measure import measure_blur_disks, measure_distortion, measure_vignetting
from lenscompare.render import render
from lenscompare.scene import load_scene

from helpers import REFERENCE_SCENES


def _run(name: str, model: str, *, spp: int, resolution=None, f_number=None) -> Run:
    scene, _ = prepare_scene(load_scene(REFERENCE_SCENES / f"{name}.toml"), ExperimentSettings())
    if resolution:
        scene = scene.with_camera(resolution=resolution)
    if f_number:
        scene = scene.with_camera(f_number=f_number)
    return Run(scene, model, "native", render(scene, model=model, spp=spp, threads=2, progress=False))


def test_lens_system_blur_disks_agree_with_a_real_ray_trace_not_with_equation_5():
    """Double Gauss at f/2.03, blur_disks at 720 x 480, 256 spp. Measured: the
    render departs from eq. 5 by up to -36 % off the axis, and agrees with the
    traced spot within 1.11 % (seeds 0-3; at 360 x 240 the noise of the disks'
    edges is larger: over 14 seeds the largest error 5.3 % and rms 1.9 % with
    the earlier Fisher-Yates pairing of lens and film strata, 10.3 % and 2.4 % with
    the hashed one)."""
    run = _run("blur_disks", "lens", spp=256, resolution=(720, 480))
    rows = [r for r in measure_blur_disks(run.scene, [run])["renders"]["lens"] if r and r["error_percent"] is not None]
    assert len(rows) >= 4
    assert all(r["expected_from"].startswith("real rays") for r in rows)
    assert max(abs(r["error_percent"]) for r in rows) < 3.0
    assert min(r["departure_from_eq5_percent"] for r in rows) < -20.0  # eq. 5 is not the lens system's blur


def test_thin_lens_blur_disks_are_equation_5_within_2_percent():
    run = _run("blur_disks", "thin", spp=256, resolution=(360, 240))
    rows = [r for r in measure_blur_disks(run.scene, [run])["renders"]["thin"] if r and r["eq5_px"] >= 3.5]
    assert len(rows) >= 3
    for r in rows:
        assert r["expected_px"] == r["eq5_px"] and r["error_percent"] == r["departure_from_eq5_percent"]
        assert abs(r["error_percent"]) < 2.0


def test_distortion_is_measured_against_the_paraxial_scale_and_matches_the_chief_ray():
    """Dot grid through the Double Gauss stopped to f/16 (little coma): each
    dot's measured distortion against the real chief ray at its field angle,
    traced through the same stopped-down lens and focus."""
    run = _run("dot_grid", "lens", spp=16, f_number=16.0)
    data = measure_distortion(run.scene, [run])["renders"]["lens"]
    assert data is not None and data["f_number"] == pytest.approx(16.0)
    fields = np.asarray(data["field_deg"])
    measured = np.asarray(data["distortion_percent"])
    traced = np.array([chief_ray_distortion_percent(run.image.camera.prescription, f,
                                                    focus_distance_m=run.scene.camera.focus_distance_m)
                       for f in fields])
    assert len(fields) > 50
    far = fields > 10.0  # near the axis 0.05 px of centroid noise is a large percentage
    difference = measured[far] - traced[far]
    # No bias (a scale fitted near the axis gave +0.035 to +0.16 pp), centroid noise only.
    assert abs(difference.mean()) < 0.01
    assert np.abs(difference).mean() < 0.02 and np.abs(difference).max() < 0.1


def test_an_ideal_lens_has_no_distortion_at_the_paraxial_scale():
    run = _run("dot_grid", "thin", spp=16)
    data = measure_distortion(run.scene, [run])["renders"]["thin"]
    far = np.asarray(data["field_deg"]) > 10.0
    distortion = np.asarray(data["distortion_percent"])[far]
    assert abs(distortion.mean()) < 0.01 and np.abs(distortion).max() < 0.08


def test_lens_system_vignetting_matches_its_real_ray_trace():
    run = _run("flat_field", "lens", spp=64)
    data = measure_vignetting(run.scene, [run])["renders"]["lens"]
    traced = data["traced"]
    assert traced["field_deg"][:4] == [5.0, 10.0, 15.0, 20.0]
    rendered = np.interp(traced["field_deg"], data["field_deg"], data["relative_illumination"])
    # The trace is for an object at infinity; the flat field is 3 m away.
    np.testing.assert_allclose(rendered, traced["relative_illumination"], atol=0.02)
    # Without the expectation: the same readings, no trace.
    bare = measure_vignetting(run.scene, [run], traced=False)["renders"]["lens"]
    assert "traced" not in bare and bare["at"] == data["at"]
