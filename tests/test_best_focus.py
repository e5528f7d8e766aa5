"""``camera.focus_mode``: the best-focus film position against a brute-force
scan of an independent spot trace, the paraxial mode unchanged, a render in
both modes, and the key's validation."""

import math

import numpy as np
import pytest

from lenscompare.cameras import camera_for
from lenscompare.lenses import (
    best_focus_film_z_mm,
    film_distance_mm,
    load_prescription,
    point_source_spot_mm,
    rms_spot_radius_mm,
    sharpest_plane_m,
    spot_diameter_mm,
    stopped_down,
    traced_spot_diameter_mm,
)
from lenscompare.metrics import find_point_sources, measure_blur_disk
from lenscompare.plan.spot_window import settled_window_px
from lenscompare.render import render
from lenscompare.scene import parse_scene

from helpers import camera_scene_text, run_cli, sphere_text


@pytest.mark.parametrize("name, focus_m, f_number", [("wide.22mm", 2.0, None), ("telephoto.250mm", 20.0, None),
                                                     ("dgauss.50mm", 2.0, 8.0)])
def test_best_focus_is_the_minimum_of_a_brute_force_scan_of_an_independent_spot_trace(name, focus_m, f_number):
    # The independent trace: a square grid of rays over the beam's footprint
    # on the first vertex plane (point_source_spot_mm), not best_focus's fan
    # of rings; it converges to the fan's spot (200 across: 0.1 %; the grid
    # over the whole first surface undersamples the rim, 3.9 % at 200); scanned over
    # film positions around the paraxial focus, with a parabola through the
    # smallest three.
    lens = load_prescription(name)
    lens = lens if f_number is None else stopped_down(lens, f_number)
    paraxial_z = lens.total_track_mm + film_distance_mm(lens, focus_m)
    best_z = best_focus_film_z_mm(lens, focus_distance_m=focus_m)
    span = 3.0 * abs(best_z - paraxial_z) + 0.01
    z = paraxial_z + np.linspace(-span, span, 25)
    diameter = np.array([spot_diameter_mm(*point_source_spot_mm(lens, height_mm=0.0, distance_mm=1000.0 * focus_m,
                                                                film_z_mm=zi, samples_across=200))
                         for zi in z])
    i = int(np.argmin(diameter))
    a, b, _ = np.polyfit(z[i - 1:i + 2], diameter[i - 1:i + 2] ** 2, 2)
    scan_z = -b / (2 * a)
    step = z[1] - z[0]
    print(f"{name}: best {best_z - paraxial_z:+.5f} mm from paraxial, scan {scan_z - paraxial_z:+.5f} mm "
          f"(step {step:.5f})")
    assert abs(scan_z - best_z) < 0.1 * step + 2e-4
    # The two traces agree on the spot there (second-moment diameter
    # 2 sqrt(2) x RMS radius), and it is smaller than at the paraxial focus.
    fan_best = 2 * math.sqrt(2) * rms_spot_radius_mm(lens, focus_distance_m=focus_m, film_z_mm=best_z)
    grid_best = spot_diameter_mm(*point_source_spot_mm(lens, height_mm=0.0, distance_mm=1000.0 * focus_m,
                                                       film_z_mm=best_z, samples_across=200))
    assert grid_best == pytest.approx(fan_best, rel=0.01)
    assert fan_best < 2 * math.sqrt(2) * rms_spot_radius_mm(lens, focus_distance_m=focus_m, film_z_mm=paraxial_z)


def lens_scene(*, focus_mode=None, lens="dgauss.50mm", f_number=None, focus_m=2.0, film_mm=(36.0, 24.0),
               resolution=(36, 24), spp=4, objects=""):
    text = camera_scene_text(model="lens", focus_distance=focus_m, film_mm=film_mm, resolution=resolution, spp=spp,
                             objects=objects)
    text = text.replace("focal_length_mm = 50.0\n", f'lens = "{lens}"\n')
    text = text.replace("f_number = 2.8\n", "" if f_number is None else f"f_number = {f_number!r}\n")
    if focus_mode is not None:
        text = text.replace("[render]", f'focus_mode = "{focus_mode}"\n\n[render]')
    return parse_scene(text)


def test_paraxial_mode_is_the_default_and_keeps_the_paraxial_film():
    default, explicit = lens_scene(), lens_scene(focus_mode="paraxial")
    assert default.camera.focus_mode == "paraxial" and default == explicit
    camera = camera_for(default)
    lens = load_prescription("dgauss.50mm")
    assert camera.film_z_mm == lens.total_track_mm + film_distance_mm(lens, 2.0)  # exactly the old film
    assert camera.focus_shift_mm == 0.0
    info = camera.to_json()
    assert info["focus_mode"] == "paraxial" and info["focus_shift_from_paraxial_mm"] == 0.0
    best = camera_for(lens_scene(focus_mode="best"))
    assert best.to_json()["focus_mode"] == "best"
    assert best.film_z_mm == pytest.approx(camera.film_z_mm + best.focus_shift_mm, abs=1e-12)
    assert best.focus_shift_mm != 0.0
    # Other models ignore the key.
    assert camera_for(lens_scene(focus_mode="best"), "pinhole") == camera_for(default, "pinhole")


def test_best_mode_renders_a_smaller_spot_than_paraxial():
    # wide.22mm wide open, a point on the 2 m focus plane: the real-ray RMS
    # spot is 16.1 um at the paraxial film and 6.1 um at the best film. A film
    # of 1.2 x 0.8 mm at 10 um pixels resolves both.
    objects = sphere_text((0.0, 0.0, 2.0), 0.0004)  # its sharp image is 0.9 px wide
    spots = {}
    for mode in ("paraxial", "best"):
        scene = lens_scene(focus_mode=mode, lens="wide.22mm", film_mm=(1.2, 0.8), resolution=(120, 80), spp=1024,
                           objects=objects)
        camera = camera_for(scene)
        pixels = render(scene, threads=2, progress=False).pixels
        (source,) = find_point_sources(pixels)
        sphere_px = 2 * 0.0004 * camera.image_scale_mm / 2.0 / camera.pixel_pitch_mm

        def measured(window_px):
            return measure_blur_disk(pixels, center_px=source.centroid_px, window_radius_px=min(window_px, 38),
                                     source_diameter_px=sphere_px).second_moment_diameter_px

        _, spots[mode] = settled_window_px(measured, start_px=38)
        expected = traced_spot_diameter_mm(camera.prescription, height_mm=0.0, distance_mm=2000.0,
                                           film_z_mm=camera.film_z_mm, samples_across=240) / camera.pixel_pitch_mm
        print(f"{mode}: measured {spots[mode]:.2f} px, traced (no window) {expected:.2f} px")
    assert spots["best"] < 0.6 * spots["paraxial"]


def test_sharpest_plane_in_paraxial_mode_is_where_best_focus_lands_on_the_paraxial_film():
    lens = load_prescription("telephoto.250mm")
    film_z = lens.total_track_mm + film_distance_mm(lens, 20.0)
    plane_m = sharpest_plane_m(lens, film_z_mm=film_z)
    assert plane_m < 20.0  # undercorrected: the sharpest plane is nearer
    assert best_focus_film_z_mm(lens, focus_distance_m=plane_m) == pytest.approx(film_z, abs=1e-9)


def test_an_unknown_focus_mode_is_refused_naming_file_and_key(write_scene):
    path = write_scene(camera_scene_text().replace("[render]", 'focus_mode = "auto"\n\n[render]'))
    result = run_cli("plan", path)
    assert result.returncode == 2
    assert str(path) in result.stderr and "camera.focus_mode" in result.stderr and "'best'" in result.stderr
    assert "Traceback" not in result.stderr
