"""Camera values (lenscompare.cameras): one frozen value per model, built once
from the scene and carried by every image; the scene's lens resolved once,
where the scene is loaded."""

from __future__ import annotations

import dataclasses
import json
import shutil

import pytest

from lenscompare.cameras import (
    CameraFrame,
    LensSystemCamera,
    PinholeCamera,
    ThickLensCamera,
    ThinLensCamera,
    camera_for,
)
from lenscompare.errors import InputError
from lenscompare.lenses import (
    film_distance_mm,
    load_prescription,
    paraxial_data,
    paraxial_image_scale_mm,
    stopped_down,
    traced_spot_diameter_mm,
)
from lenscompare.optics import circle_of_confusion_mm, focus_film_distance_mm
from lenscompare.render import render
from lenscompare.scene import load_scene, parse_scene

from helpers import REFERENCE_SCENES, REPO, camera_scene_text, sphere_text

SINGLET = REPO / "tests" / "data" / "lenses" / "thin_singlet.dat"


def test_each_model_has_its_value_type_and_the_geometry_of_eq4():
    scene = parse_scene(camera_scene_text(focal_length_mm=50.0, f_number=2.0, focus_distance=2.0,
                                          resolution=(360, 240)))
    d_prime = focus_film_distance_mm(2000.0, 50.0)
    pinhole, thin = camera_for(scene, "pinhole"), camera_for(scene, "thin")
    assert isinstance(pinhole, PinholeCamera) and isinstance(thin, ThinLensCamera)
    for camera in (pinhole, thin):
        assert camera.film_distance_mm == pytest.approx(d_prime, rel=1e-15)
        assert camera.image_scale_mm == camera.film_distance_mm
        assert camera.pixel_pitch_mm == pytest.approx(0.1)
        assert camera.frame == CameraFrame.of(scene.camera)
    assert pinhole.aperture_diameter_mm == 0.0 and pinhole.f_number is None
    assert thin.aperture_diameter_mm == pytest.approx(25.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        thin.focal_length_mm = 35.0


def test_thick_value_carries_the_gap_and_otherwise_the_thin_geometry():
    text = camera_scene_text(model="thick").replace("focal_length_mm = 50.0", "focal_length_mm = 50.0\n"
                                                                               "principal_plane_gap_mm = -7.5")
    scene = parse_scene(text)
    thick, thin = camera_for(scene, "thick"), camera_for(scene, "thin")
    assert isinstance(thick, ThickLensCamera) and thick.principal_plane_gap_mm == -7.5
    assert (thick.film_distance_mm, thick.aperture_diameter_mm) == (thin.film_distance_mm, thin.aperture_diameter_mm)
    assert thick.to_json()["principal_plane_gap_mm"] == -7.5


def test_lens_system_value_from_the_prescription():
    scene = load_scene(REFERENCE_SCENES / "showcase.toml").with_camera(lens="dgauss.50mm", f_number=4.0)
    camera = camera_for(scene, "lens")
    lens = load_prescription("dgauss.50mm")
    data = paraxial_data(lens)
    assert isinstance(camera, LensSystemCamera)
    assert camera.f_number == pytest.approx(4.0, rel=1e-12)
    assert camera.focal_length_mm == pytest.approx(data.effective_focal_length_mm, rel=1e-12)
    film_z = data.total_track_mm + film_distance_mm(lens, scene.camera.focus_distance_m)
    assert camera.film_z_mm == pytest.approx(film_z, rel=1e-14)
    assert camera.film_distance_mm == pytest.approx(film_z - data.rear_principal_plane_mm, rel=1e-14)
    # JSON metadata is plain data.
    json.dumps(camera.to_json())


def test_paraxial_image_scale_is_the_focal_length_at_infinity_and_grows_when_focused_closer():
    lens = load_prescription("dgauss.50mm")
    data = paraxial_data(lens)
    at_infinity = data.total_track_mm + data.back_focal_length_mm
    assert paraxial_image_scale_mm(lens, at_infinity) == pytest.approx(data.effective_focal_length_mm, rel=1e-12)
    scales = [paraxial_image_scale_mm(lens, data.total_track_mm + film_distance_mm(lens, d)) for d in (10, 2, 0.5)]
    assert data.effective_focal_length_mm < scales[0] < scales[1] < scales[2]
    # Through the entrance pupil, not H': at 2 m the two differ by about 0.16 %.
    film_z = data.total_track_mm + film_distance_mm(lens, 2.0)
    assert (film_z - data.rear_principal_plane_mm) / scales[1] - 1.0 == pytest.approx(0.0016, abs=3e-4)


def _singlet_spot_against_eq5(f_number: float, **options) -> tuple[float, float]:
    lens = stopped_down(load_prescription(SINGLET), f_number)
    data = paraxial_data(lens)
    film_z = data.total_track_mm + film_distance_mm(lens, 3.0)
    traced = traced_spot_diameter_mm(lens, height_mm=0.0, distance_mm=1000.0, film_z_mm=film_z, **options)
    # Eq. 5 for a thick lens: object and focus distances from H, film from H'.
    h_offset = data.front_principal_plane_mm - data.entrance_pupil_position_mm
    eq5 = circle_of_confusion_mm(1000.0 - h_offset, focus_distance_mm=3000.0 - h_offset,
                                 focal_length_mm=data.effective_focal_length_mm,
                                 aperture_diameter_mm=data.entrance_pupil_diameter_mm)
    return traced, eq5


def test_traced_spot_of_a_slow_singlet_on_the_axis_tends_to_equation_5():
    """A 100 mm singlet's real-ray spot of a point 1 m away, film focused at
    3 m, approaches eq. 5 as the stop closes and spherical aberration fades
    (measured: -3.7 % at f/10, -1.0 % at f/20, -0.33 % at f/40)."""
    departures = [abs(t / e - 1.0) for t, e in (_singlet_spot_against_eq5(n) for n in (10.0, 20.0, 40.0))]
    assert departures[0] > departures[1] > departures[2]
    assert departures[2] < 0.005 and departures[0] > 0.02
    traced, eq5 = _singlet_spot_against_eq5(40.0, window_radius_mm=0.25 * 0.1737)
    assert traced < 0.6 * eq5  # a window smaller than the spot cuts it


def test_every_image_carries_the_camera_it_was_rendered_through():
    scene = parse_scene(camera_scene_text(resolution=(36, 24), spp=2, objects=sphere_text((0, 0, 2), 0.1)))
    for model in ("pinhole", "thin"):
        image = render(scene, model=model, threads=2, progress=False)
        assert image.camera == camera_for(scene, model)
        assert image.metadata["camera"] == image.camera.to_json()


def test_adaptive_images_carry_their_variance():
    scene = parse_scene(camera_scene_text(resolution=(36, 24), spp=8, objects=sphere_text((0, 0, 3), 0.3)))
    image = render(scene, spp=8, adaptive=True, sampler="sobol", threads=2, progress=False)
    assert image.variance.shape == (24, 36)
    assert (image.variance >= 0).all() and image.variance.max() > 0


def test_a_lens_file_beside_the_scene_is_found_from_anywhere(tmp_path, monkeypatch):
    """Resolved once, at load: shipped name, else beside the scene, else as given."""
    folder = tmp_path / "project"
    folder.mkdir()
    shutil.copy(SINGLET, folder / "my.dat")
    text = camera_scene_text(model="lens").replace('model = "lens"', 'model = "lens"\nlens = "my.dat"')
    (folder / "scene.toml").write_text(text.replace("f_number = 2.8", "f_number = 8.0"))
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    scene = load_scene(folder / "scene.toml")
    assert scene.camera.lens.source == str(folder / "my.dat")
    assert scene.camera.lens == load_prescription(folder / "my.dat")
    # A shipped name wins over a file of that name.
    (folder / "dgauss.50mm").write_text("not a lens")
    assert scene.with_camera(lens="dgauss.50mm").camera.lens == load_prescription("dgauss.50mm")


def test_a_missing_lens_is_refused_at_load_naming_the_scene_and_key(tmp_path):
    path = tmp_path / "scene.toml"
    path.write_text(camera_scene_text().replace('model = "thin"', 'model = "thin"\nlens = "nowhere.dat"'))
    with pytest.raises(InputError) as error:
        load_scene(path)
    assert error.value.source == str(path) and error.value.key == "camera.lens"
    assert "nowhere.dat" in str(error.value)


def test_an_f_number_within_rounding_of_the_lens_own_is_wide_open():
    """f/5 is not refused for a lens whose own f-number is 5.00002 (tolerance 1e-4)."""
    lens = load_prescription("dgauss.50mm")
    own = paraxial_data(lens).f_number
    assert paraxial_data(stopped_down(lens, own * (1 - 5e-5))).f_number == pytest.approx(own, rel=1e-12)
    with pytest.raises(InputError) as error:
        stopped_down(lens, own * (1 - 2e-4))
    # Enough digits to show the two differ.
    asked, wide_open = str(error.value).split("f/")[1].split()[0], str(error.value).split("(f/")[1].split()[0]
    assert asked != wide_open
    assert float(wide_open) == pytest.approx(own, rel=1e-4) and float(asked) == pytest.approx(own * (1 - 2e-4),
                                                                                             rel=1e-4)
