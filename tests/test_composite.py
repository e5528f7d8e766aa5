"""The composite camera (cameras/composite.py, native cameras/composite.h) and
its traced maps (lenses/maps.py): the thin lens bit for bit without tables,
thread-count independence, and per-effect fidelity against the full lens
system's converged image within the planner's tolerances. Each fidelity test
also shows the composite WITHOUT that effect's part failing the same check,
so the check can fail."""

import json
import math

import numpy as np
import pytest

from lenscompare.cameras import ThinLensCamera, camera_for
from lenscompare.image import read_exr
from lenscompare.lenses import radial_maps
from lenscompare.metrics import dot_centroids, find_point_sources, match_points, relative_illumination
from lenscompare.plan import plan_scene
from lenscompare.render import render
from lenscompare.scene import load_scene, parse_scene

from helpers import MINIMAL_SCENE, REFERENCE_SCENES, camera_scene_text, run_cli, sphere_text

ALL = ("defocus", "distortion", "vignetting")


def lit_scene(lens="dgauss.50mm", f_number=8.0, resolution=(48, 32)):
    text = MINIMAL_SCENE.replace("resolution = [36, 24]", f"resolution = [{resolution[0]}, {resolution[1]}]")
    return parse_scene(text).with_camera(lens=lens, f_number=f_number)


# --- bit for bit, and the same image for any thread count -------------------------------------------------

def test_composite_of_defocus_alone_is_the_thin_lens_bit_for_bit():
    scene = lit_scene()
    composite = camera_for(scene, "composite", effects=("defocus",))
    thin = ThinLensCamera(frame=composite.frame, film=composite.film, focus_distance_m=composite.focus_distance_m,
                          focal_length_mm=composite.focal_length_mm, film_distance_mm=composite.paraxial_scale_mm,
                          f_number=composite.f_number, aperture_diameter_mm=composite.aperture_diameter_mm)
    a = render(scene, camera=composite, spp=8, threads=2).pixels
    b = render(scene, camera=thin, spp=8, threads=2).pixels
    assert np.array_equal(a, b) and a.max() > 0
    # Without a lens the composite of defocus is the scene's own thin lens.
    plain = parse_scene(MINIMAL_SCENE)
    assert np.array_equal(render(plain, effects=("defocus",), spp=4).pixels, render(plain, model="thin", spp=4).pixels)


def test_composite_tables_change_the_image_and_threads_do_not():
    scene = lit_scene(f_number=4.0)
    one = render(scene, effects=ALL, spp=8, threads=1)
    two = render(scene, effects=ALL, spp=8, threads=2)
    assert np.array_equal(one.pixels, two.pixels)
    assert not np.array_equal(one.pixels, render(scene, effects=("defocus",), spp=8, threads=1).pixels)
    assert one.metadata["model"] == "composite" and one.metadata["effects"] == list(ALL)
    assert np.isfinite(one.pixels).all()


# --- the maps ----------------------------------------------------------------------------------------------

def test_maps_are_finite_one_on_the_axis_monotonic_and_memoised():
    camera = camera_for(lit_scene(), "lens")
    kwargs = dict(film_z_mm=camera.film_z_mm, paraxial_scale_mm=camera.paraxial_scale_mm,
                  focus_distance_m=camera.focus_distance_m, film_half_diagonal_mm=camera.film.half_diagonal_mm)
    maps = radial_maps(camera.prescription, **kwargs)
    assert maps is radial_maps(camera.prescription, **kwargs)
    assert maps.illumination[0] == 1.0 and maps.screen_scale[0] == 1.0 and maps.covers_film
    assert np.all(np.diff(maps.field_tangent) > 0) and np.isfinite(maps.screen_scale).all()
    # The Double Gauss at f/8: barrel distortion (the film corner looks 1-2 % further out) and a
    # 15-25 % corner falloff.
    assert 1.005 < maps.screen_scale[-1] < 1.03 and 0.7 < maps.illumination[-1] < 0.9


def test_fisheye_composite_is_black_outside_the_image_circle_and_never_nan():
    scene = parse_scene(MINIMAL_SCENE.replace("resolution = [36, 24]", "resolution = [60, 40]")
                        + "\n[background]\ncolor = [1.0, 1.0, 1.0]\n").with_camera(lens="fisheye.10mm", f_number=None)
    camera = camera_for(scene, "composite", effects=ALL)
    assert camera.maps.max_radius_mm < camera.film.half_diagonal_mm
    image = render(scene, camera=camera, spp=4, threads=2).pixels
    assert np.isfinite(image).all() and image[0, 0].max() == 0.0 and image[20, 30].min() > 0.5


# --- fidelity against the lens system, effect by effect -----------------------------------------------------

def flat_field(lens, f_number):
    return load_scene(REFERENCE_SCENES / "flat_field.toml").with_camera(lens=lens, f_number=f_number,
                                                                         resolution=(120, 80))


@pytest.mark.parametrize("lens, f_number", [("dgauss.50mm", 8.0), ("dgauss.50mm", 2.8), ("wide.22mm", 5.6),
                                            ("fisheye.10mm", 5.6)])
def test_vignetting_matches_the_lens_system_within_the_tolerance(lens, f_number):
    scene = flat_field(lens, f_number)
    plan = plan_scene(scene, measure_costs=False)
    assert plan.model == "composite" and "vignetting" in plan.simulated
    falloff = lambda image: 100.0 * relative_illumination(image.pixels, n_bins=20)[1]  # noqa: E731
    lens_ri = falloff(render(scene, model="lens", spp=256, threads=2))
    error = np.abs(falloff(render(scene, effects=plan.composite_effects, spp=16, threads=2)) - lens_ri).max()
    without = np.abs(falloff(render(scene, effects=("distortion",), spp=16, threads=2)) - lens_ri).max()
    print(f"{lens} f/{f_number}: falloff error {error:.2f} pp (without the part {without:.1f} pp)")
    assert error < plan.tolerance_percent < without


def centroid_shifts_px(image_true, image_test):
    true, test = dot_centroids(image_true.pixels), dot_centroids(image_test.pixels)
    i_test, i_true = match_points(test, true, max_distance_px=8.0)
    assert len(i_test) >= 0.95 * len(true)
    return np.hypot(*(test[i_test] - true[i_true]).T)


@pytest.mark.parametrize("lens, f_number, part_matters", [("dgauss.50mm", 8.0, True), ("dgauss.50mm", 16.0, True),
                                                          ("wide.22mm", 5.6, None)])
def test_distortion_matches_the_lens_system_within_the_tolerance(lens, f_number, part_matters):
    scene = load_scene(REFERENCE_SCENES / "dot_grid.toml").with_camera(lens=lens, f_number=f_number)
    plan = plan_scene(scene, measure_costs=False)
    lens_image = render(scene, model="lens", spp=64, threads=2)
    composite = render(scene, effects=ALL, spp=64, threads=2)
    shift = centroid_shifts_px(lens_image, composite).max()
    without = centroid_shifts_px(lens_image, render(scene, effects=("defocus", "vignetting"), spp=64, threads=2))
    print(f"{lens} f/{f_number}: largest dot shift {shift:.3f} px (without the part {without.max():.2f} px)")
    assert shift < plan.tolerance_px
    if part_matters is not None:
        assert (without.max() > plan.tolerance_px) == part_matters == plan.needed["distortion"]
    # (wide.22mm: the planner sizes distortion at the corner, 0.30 px; mid-field it peaks near 0.55 px.)


def test_defocus_matches_the_lens_system_within_the_tolerance():
    objects = "".join(sphere_text(((i - 1.5) / 1.5 * 0.2 * z, 0.03 * z, z), 0.0008 * z)
                      for i, z in enumerate([0.6, 0.9, 1.5, 4.0]))
    text = camera_scene_text(model="lens", focus_distance=1.5, resolution=(240, 160), spp=64, objects=objects)
    scene = parse_scene(text).with_camera(lens="dgauss.50mm", f_number=8.0)
    plan = plan_scene(scene, measure_costs=False)
    assert plan.model == "composite" and "defocus" in plan.composite_effects

    def diameters(image):
        return [s.second_moment_diameter_px for s in sorted(find_point_sources(image.pixels),
                                                            key=lambda s: s.centroid_px[0])]

    lens = diameters(render(scene, model="lens", spp=256, threads=2))
    composite = diameters(render(scene, effects=plan.composite_effects, spp=256, threads=2))
    pinhole = diameters(render(scene, effects=("distortion", "vignetting"), spp=256, threads=2))
    assert len(lens) == len(composite) == len(pinhole) == 4
    error = max(abs(a - b) for a, b in zip(lens, composite))
    without = max(abs(a - b) for a, b in zip(lens, pinhole))
    print(f"blur-disk diameters lens {np.round(lens, 2)}, composite {np.round(composite, 2)}: error {error:.2f} px")
    assert error < plan.tolerance_px < without


# --- the command line and the scene key ---------------------------------------------------------------------

def test_render_effects_on_the_command_line_and_in_the_scene(tmp_path, write_scene):
    text = MINIMAL_SCENE.replace('model = "thin"', 'model = "thin"\nlens = "dgauss.50mm"')
    scene = write_scene(text)
    out = tmp_path / "c.exr"
    done = run_cli("render", scene, "-o", out, "--effects", "defocus,vignetting", "--spp", "2", "--json")
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert report["model"] == "composite" and report["effects"] == ["defocus", "vignetting"]
    assert read_exr(out).pixels.shape == (24, 36, 3)

    refused = run_cli("render", scene, "-o", tmp_path / "a.exr", "--effects", "defocus,aberrations")
    assert refused.returncode == 2 and "--effects" in refused.stderr and "--model lens" in refused.stderr
    unknown = run_cli("render", scene, "-o", tmp_path / "b.exr", "--effects", "defocus,bokeh")
    assert unknown.returncode == 2 and "--effects" in unknown.stderr and "Traceback" not in unknown.stderr

    keyed = write_scene(text.replace("spp = 4", 'spp = 2\neffects = ["distortion"]'), "keyed.toml")
    done = run_cli("render", keyed, "-o", tmp_path / "k.exr", "--json")
    assert done.returncode == 0 and json.loads(done.stdout)["effects"] == ["distortion"]
    for effects, words in (('["bokeh"]', "unknown effect"), ('["aberrations"]', "--model lens"), ('"defocus"', "array")):
        bad = write_scene(text.replace("spp = 4", f"spp = 2\neffects = {effects}"), "bad.toml")
        failed = run_cli("render", bad, "-o", tmp_path / "x.exr")
        assert failed.returncode == 2 and "bad.toml" in failed.stderr and "render.effects" in failed.stderr
        assert words in failed.stderr and "Traceback" not in failed.stderr
    assert not (tmp_path / "x.exr").exists() and math.isfinite(read_exr(out).pixels.sum())
