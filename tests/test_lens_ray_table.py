"""The lens system's rays from a table (``[render] lens_rays = "table"``,
native/src/lens/lens_ray_table.h): rays traced once per camera at the nodes of
a grid per exit-pupil ring, interpolated per sample.

What must hold: the interpolated rays leave the lens where the traced ones do,
to a small fraction of a pixel's angle, for every shipped lens and the
hard-case lenses (a cemented zero-thickness layer, flat fronts, a pinpoint
stop); they pass or are blocked as the traced ones are, but for a sliver
along the rims; where a table cannot get that close (a strongly aberrated
ball-like singlet that reflects totally at its rim) or cannot hold the lens
at all (a bladed stop is not round) it is refused and the render traces; a render from the table differs from the
traced render with the same samples by much less than the render's own
noise; the flat field's centre still reads 1; the image is the same for any
thread count and lens-trace kernel; a spectral render takes it unless the
lens disperses.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from helpers import REFERENCE_SCENES
from lenscompare._native import diagnostics
from lenscompare.cameras import camera_for
from lenscompare.cameras.lens_ray_table import batch_rays
from lenscompare.errors import InputError
from lenscompare.render import render
from lenscompare.scene import load_scene

ROOT = Path(__file__).resolve().parent.parent
TEST_LENSES = ROOT / "tests" / "data" / "lenses"
CELLS = (16, 64)  # lenscompare.cameras.lens.LENS_RAY_TABLE_CELLS

# (lens, f-number, blades) -> bound on the 99th percentile of the direction
# error, in pixels' angles, at 16 x 64 cells (measured, 2^16 samples: Double
# Gauss 0.009, 0.0008 at f/8, 0.0005 at f/1000; wide angle 0.013, fisheye
# 0.010, telephoto 0.018; the test lenses 0.014-0.016).
# The weight sum departs from the traced by at most 0.16 % (f/1000).
CASES = [
    ("dgauss.50mm", None, 0, 0.03),
    ("dgauss.50mm", 8.0, 0, 0.01),
    ("dgauss.50mm", 1000.0, 0, 0.01),
    ("wide.22mm", None, 0, 0.05),
    ("fisheye.10mm", None, 0, 0.05),
    ("telephoto.250mm", None, 0, 0.06),
    (str(TEST_LENSES / "cemented_zero_layer.dat"), None, 0, 0.05),
    (str(TEST_LENSES / "planoconvex_flat_front.dat"), None, 0, 0.05),
    (str(TEST_LENSES / "planoconvex_nearly_flat_front.dat"), None, 0, 0.05),
]


def _scene(lens, f_number=None, blades=0, *, resolution=(240, 160)):
    return load_scene(REFERENCE_SCENES / "showcase.toml").with_camera(
        lens=lens, f_number=f_number, aperture_blades=blades, resolution=resolution, focal_length_mm=None)


@pytest.mark.parametrize("lens, f_number, blades, p99_px", CASES)
def test_table_rays_leave_the_lens_where_traced_rays_do(lens, f_number, blades, p99_px):
    scene = _scene(lens, f_number, blades)
    model = camera_for(scene, "lens")
    camera = model.native()
    rng = np.random.default_rng(11)
    n = 1 << 16
    width, height = scene.camera.resolution
    raster = np.column_stack([rng.uniform(0, width, n), rng.uniform(0, height, n)]).astype(np.float32)
    lens_sample = rng.uniform(0, 1, (n, 2)).astype(np.float32)
    traced = batch_rays(camera, raster, lens_sample)
    camera.use_ray_table(*CELLS)
    assert camera.uses_ray_table
    table = batch_rays(camera, raster, lens_sample)
    assert all(np.isfinite(a).all() for a in table)
    passed_traced, passed = traced[2] > 0, table[2] > 0
    assert passed_traced.mean() > 0.3
    # Only a sliver along the rims passes one way and not the other.
    assert np.mean(passed != passed_traced) < 0.01
    both = passed & passed_traced
    pixel_angle = (model.film.width_mm / width) / model.focal_length_mm
    error_px = np.linalg.norm(table[1][both] - traced[1][both], axis=1) / pixel_angle
    assert np.percentile(error_px, 99) < p99_px
    assert np.abs(np.linalg.norm(table[1][both], axis=1) - 1).max() < 1e-6
    assert table[2].sum() / traced[2].sum() == pytest.approx(1.0, abs=0.005)
    # Each table ray starts near the traced ray's line (where it leaves the first
    # surface, to interpolation): the traced line's point at the same depth.
    # Measured 99th percentile: 0.0004 mm (f/1000) to 0.035 mm (Double Gauss wide open).
    forward = np.array(scene.camera.look_at) - np.array(scene.camera.position)
    forward /= np.linalg.norm(forward)
    start = traced[0][both] + traced[1][both] * (
        np.einsum("ij,j->i", table[0][both] - traced[0][both], forward)
        / np.einsum("ij,j->i", traced[1][both], forward))[:, None]
    offset_mm = np.percentile(np.linalg.norm(start - table[0][both], axis=1), 99) * 1e3
    assert offset_mm < 0.1


@pytest.mark.parametrize("lens", ["dgauss.50mm", "wide.22mm", "fisheye.10mm", "telephoto.250mm",
                                  str(TEST_LENSES / "cemented_zero_layer.dat")])
def test_the_pick_is_mirror_symmetric_so_half_a_table_holds_it(lens):
    # The table holds u.y in [0, 1/2] and turns the rest over (lens_ray_table.h):
    # for a film point on the lens frame's x axis, the traced rays at u.y and
    # 1 - u.y are mirror images across the meridional plane.
    scene = _scene(lens)
    camera = camera_for(scene, "lens").native()
    diagnostics.set_lens_trace_precision(camera, "double")
    width, height = scene.camera.resolution
    rng = np.random.default_rng(4)
    n = 4096
    raster = np.column_stack([rng.uniform(0, width / 2, n), np.full(n, height / 2)]).astype(np.float32)
    lens_sample = rng.uniform(0, 1, (n, 2)).astype(np.float32)
    turned = lens_sample.copy()
    turned[:, 1] = 1 - lens_sample[:, 1]
    rays, mirrored = ([np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n, np.float32)] for _ in range(2))
    diagnostics.generate_lens_rays_batched(camera, raster, lens_sample, *rays)
    diagnostics.generate_lens_rays_batched(camera, raster, turned, *mirrored)
    assert np.array_equal(rays[2] > 0, mirrored[2] > 0)
    both = rays[2] > 0
    assert both.mean() > 0.5
    np.testing.assert_allclose(mirrored[2][both], rays[2][both], rtol=1e-6)
    # The world's mirror plane holds the camera's right and forward axes: the
    # world "up" components turn over, the others stay (measured 1e-9).
    forward = np.array(scene.camera.look_at, float) - np.array(scene.camera.position, float)
    forward /= np.linalg.norm(forward)
    right = np.cross([0.0, 1.0, 0.0], forward)
    right /= np.linalg.norm(right)
    up = np.cross(forward, right)
    reflect = np.eye(3) - 2 * np.outer(up, up)
    np.testing.assert_allclose(mirrored[1][both], rays[1][both] @ reflect, atol=1e-7)


def test_render_rows_from_the_table_match_its_double_rays():
    # The render's packets take the table's rays through the world step in
    # float (lens_to_world.h); the diagnostic batch path goes through double.
    scene = _scene("dgauss.50mm")
    camera = camera_for(scene, "lens").native()
    camera.use_ray_table(*CELLS)
    rng = np.random.default_rng(6)
    n = 1 << 14
    raster = np.column_stack([rng.uniform(0, 240, n), rng.uniform(0, 160, n)]).astype(np.float32)
    lens_sample = rng.uniform(0, 1, (n, 2)).astype(np.float32)
    rows = batch_rays(camera, raster, lens_sample)
    double = [np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n, np.float32)]
    diagnostics.generate_lens_rays_batched(camera, raster, lens_sample, *double)
    assert np.array_equal(rows[2] > 0, double[2] > 0)
    both = rows[2] > 0
    np.testing.assert_allclose(rows[2][both], double[2][both], rtol=1e-6)
    np.testing.assert_allclose(rows[1][both], double[1][both], atol=1e-6)
    np.testing.assert_allclose(rows[0][both], double[0][both], atol=1e-6)  # metres: a micron


def test_table_render_differs_from_the_traced_by_far_less_than_noise():
    scene = _scene("dgauss.50mm", resolution=(120, 80))
    traced = render(scene, model="lens", spp=64, seed=5, threads=2, progress=False).pixels
    other_seed = render(scene, model="lens", spp=64, seed=6, threads=2, progress=False).pixels
    image = render(scene, model="lens", spp=64, seed=5, threads=2, progress=False, lens_rays="table")
    info = image.metadata["lens_rays"]
    assert (info["from"], info["radial_cells"], info["around_cells"]) == ("table", *CELLS)
    assert info["p999_error_px"] < info["tolerance_px"]
    norm = np.sqrt(np.mean(traced.astype(float) ** 2))
    noise = np.sqrt(np.mean((other_seed.astype(float) - traced) ** 2)) / norm
    difference = np.sqrt(np.mean((image.pixels.astype(float) - traced) ** 2)) / norm
    # Measured: noise 0.0337, difference 0.0038, means 0.99992 (the same samples, rays a hundredth of a pixel apart).
    assert difference < 0.3 * noise
    assert image.pixels.mean() / traced.mean() == pytest.approx(1.0, abs=0.002)


@pytest.mark.parametrize("f_number", [None, 1000.0])
def test_flat_field_centre_reads_one_and_the_corner_as_traced(f_number):
    scene = load_scene(REFERENCE_SCENES / "flat_field.toml").with_camera(
        lens="dgauss.50mm", f_number=f_number, resolution=(60, 40), focal_length_mm=None)
    images = {rays: render(scene, model="lens", spp=256, seed=1, threads=2, progress=False,
                           lens_rays=rays).pixels.mean(axis=2) for rays in ("traced", "table")}
    centre = images["table"][18:22, 28:32].mean()
    assert centre == pytest.approx(1.0, abs=0.01)
    corners = {rays: np.mean([im[:3, :3].mean(), im[-3:, -3:].mean()]) for rays, im in images.items()}
    assert corners["table"] == pytest.approx(corners["traced"], rel=0.01)


def test_same_image_for_any_thread_count_and_kernel():
    scene = _scene("fisheye.10mm", resolution=(64, 42))  # the fisheye's TIR nodes send cells to the exact trace
    model = camera_for(scene, "lens")
    images = []
    for threads in (1, 2):
        images.append(render(scene, model="lens", spp=8, seed=2, threads=threads, progress=False,
                             lens_rays="table").pixels)
    assert images[0].tobytes() == images[1].tobytes()
    # The cells the table cannot answer go through the lens trace's kernel: every one the same rays.
    rng = np.random.default_rng(3)
    raster = np.column_stack([rng.uniform(0, 64, 1 << 14), rng.uniform(0, 42, 1 << 14)]).astype(np.float32)
    lens_sample = rng.uniform(0, 1, (1 << 14, 2)).astype(np.float32)
    camera = model.native()
    camera.use_ray_table(*CELLS)
    by_kernel = []
    for kernel in diagnostics.lens_trace_kernels():
        diagnostics.set_lens_trace_kernel(camera, kernel)
        by_kernel.append(b"".join(a.tobytes() for a in batch_rays(camera, raster, lens_sample)))
    assert len(set(by_kernel)) == 1


def test_a_table_too_far_off_is_refused_and_the_render_traces():
    # R = 10 mm into n = 1.9: spherical aberration so strong that interpolated rays
    # stray by a pixel or more (99th percentile 1.35 px at 16 x 64, 0.97 at 32 x 128).
    scene = _scene(str(TEST_LENSES / "tir_prism.dat"), resolution=(48, 32))
    traced = render(scene, model="lens", spp=4, seed=1, threads=2, progress=False)
    image = render(scene, model="lens", spp=4, seed=1, threads=2, progress=False, lens_rays="table")
    info = image.metadata["lens_rays"]
    assert info["from"] == "traced" and info["p999_error_px"] > info["tolerance_px"]
    assert image.pixels.tobytes() == traced.pixels.tobytes()


def test_a_pinpoint_stop_whose_rim_sliver_is_too_wide_is_refused():
    # At f/10000 the Double Gauss's pupil is so small that the cells along its rim,
    # where interpolation passes rays the trace blocks or the reverse, hold 2.2 % of the
    # samples (f/1000: 0.4 %, f/3000: 0.9 %): over the check's 1 %, so the render traces.
    from lenscompare.cameras.lens_ray_table import ONE_WAY_TOLERANCE
    scene = _scene("dgauss.50mm", 10000.0, resolution=(48, 32))
    traced = render(scene, model="lens", spp=4, seed=1, threads=2, progress=False)
    image = render(scene, model="lens", spp=4, seed=1, threads=2, progress=False, lens_rays="table")
    info = image.metadata["lens_rays"]
    assert info["from"] == "traced" and info["passing_one_way_only"] > ONE_WAY_TOLERANCE
    assert info["p999_error_px"] < info["tolerance_px"]  # the rays themselves were close
    assert image.pixels.tobytes() == traced.pixels.tobytes()


def test_the_check_compares_with_the_trace_even_on_a_camera_with_a_table():
    from lenscompare.cameras.lens_ray_table import use_ray_table
    model = camera_for(_scene("wide.22mm", resolution=(64, 42)), "lens")
    native = model.native()
    first = use_ray_table(model, native)
    again = use_ray_table(model, native)  # not the table against itself (error 0)
    assert first == again and again["p999_error_px"] > 0


def test_the_kept_grid_has_its_own_pencils():
    # The grids are tried without re-measuring the tile pencils, then the kept
    # grid's are measured once: they must be those a direct build measures
    # (the table's rays'), not the traced rays' left from before.
    from lenscompare.cameras.lens_ray_table import use_ray_table
    model = camera_for(_scene("dgauss.50mm", resolution=(64, 42)), "lens")
    checked, direct, traced = model.native(), model.native(), model.native()
    assert use_ray_table(model, checked)["from"] == "table"
    direct.use_ray_table(*CELLS)
    for rect in ((0, 0, 16, 16), (24, 10, 40, 26), (48, 26, 64, 42)):
        pencil = diagnostics.lens_pencil(checked, *rect)
        assert pencil == diagnostics.lens_pencil(direct, *rect)
        assert pencil != diagnostics.lens_pencil(traced, *rect)  # so the test can tell them apart


@pytest.mark.parametrize("rotation_deg", [0.0, 10.0])
def test_a_bladed_stop_is_refused_and_the_render_traces(rotation_deg):
    # The table holds a film point on +x and turns its rays to the point's azimuth; blades do
    # not turn with it (taken, the pentagon turned with the film point: 0.62 % of rays passed one
    # way only, and each pixel's bokeh had its own orientation).
    scene = _scene("dgauss.50mm", blades=5, resolution=(48, 32)).with_camera(aperture_rotation_deg=rotation_deg)
    image = render(scene, model="lens", spp=4, seed=1, threads=2, progress=False, lens_rays="table")
    assert image.metadata["lens_rays"]["from"] == "traced" and "blade" in image.metadata["lens_rays"]["reason"]
    assert image.pixels.tobytes() == render(scene, model="lens", spp=4, seed=1, threads=2,
                                            progress=False).pixels.tobytes()
    native = camera_for(scene, "lens").native()
    native.use_ray_table(*CELLS)
    assert not native.uses_ray_table


def test_spectral_renders_take_the_table_unless_the_lens_disperses():
    # Without dispersion every wavelength rides one ray: the table's, as in RGB.
    scene = _scene("dgauss.50mm", resolution=(48, 32))
    traced = render(scene, model="lens", spp=16, seed=3, threads=2, progress=False, spectral=True).pixels
    table = render(scene, model="lens", spp=16, seed=3, threads=2, progress=False, spectral=True,
                   lens_rays="table")
    assert table.metadata["lens_rays"]["from"] == "table"
    norm = np.sqrt(np.mean(traced.astype(float) ** 2))
    assert np.sqrt(np.mean((table.pixels.astype(float) - traced) ** 2)) / norm < 0.02
    # With dispersion each wavelength is traced through its glass.
    dispersive = _scene(str(TEST_LENSES / "dgauss_abbe.dat"), resolution=(32, 20))
    image = render(dispersive, model="lens", spp=4, threads=2, progress=False, spectral=True, lens_rays="table")
    assert image.metadata["lens_rays"]["from"] == "traced" and "disperses" in image.metadata["lens_rays"]["reason"]
    assert image.pixels.tobytes() == render(dispersive, model="lens", spp=4, threads=2, progress=False,
                                            spectral=True).pixels.tobytes()


def test_lens_rays_setting_is_checked(tmp_path):
    text = (REFERENCE_SCENES / "showcase.toml").read_text().replace("[render]", '[render]\nlens_rays = "tabel"', 1)
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(InputError, match="render.lens_rays"):
        load_scene(path)
    with pytest.raises(InputError, match="--lens-rays"):
        render(_scene("dgauss.50mm", resolution=(8, 6)), model="lens", spp=1, lens_rays="exact")
    native = camera_for(_scene("dgauss.50mm", resolution=(8, 6)), "lens").native()
    for cells in ((-1, 4), (4, -1), (257, 64), (16, 1026), (16, 63)):  # around: even (the half table)
        with pytest.raises(ValueError, match="ray table cells"):
            native.use_ray_table(*cells)
    assert not native.uses_ray_table


@pytest.mark.parametrize("options", [
    {"lens_mirrors": True},               # one look-up serves a pixel and its mirror images
    {"adaptive": True},                   # the second pass's counts differ per pixel
    {"sampler": "sobol"},
], ids=["mirrors", "adaptive", "sobol"])
def test_table_composes_with_the_other_render_options(options):
    scene = _scene("dgauss.50mm", resolution=(64, 42))
    traced = render(scene, model="lens", spp=64, seed=4, threads=2, progress=False, **options).pixels
    images = [render(scene, model="lens", spp=64, seed=4, threads=threads, progress=False, lens_rays="table",
                     **options) for threads in (1, 2)]
    assert images[0].metadata["lens_rays"]["from"] == "table"
    assert images[0].pixels.tobytes() == images[1].pixels.tobytes()
    norm = np.sqrt(np.mean(traced.astype(float) ** 2))
    assert np.sqrt(np.mean((images[0].pixels.astype(float) - traced) ** 2)) / norm < 0.02
    assert images[0].pixels.mean() / traced.mean() == pytest.approx(1.0, abs=0.003)


def test_moving_camera_with_the_table():
    scene = load_scene(REFERENCE_SCENES / "moving_showcase.toml").with_camera(
        lens="dgauss.50mm", f_number=None, resolution=(48, 32), focal_length_mm=None)
    traced = render(scene, model="lens", spp=32, seed=2, threads=2, progress=False).pixels
    table = render(scene, model="lens", spp=32, seed=2, threads=2, progress=False, lens_rays="table").pixels
    assert np.isfinite(table).all()
    norm = np.sqrt(np.mean(traced.astype(float) ** 2))
    assert np.sqrt(np.mean((table.astype(float) - traced) ** 2)) / norm < 0.02


def test_model_auto_takes_the_table_for_a_lens_system_plan_within_tolerance(tmp_path):
    from lenscompare.plan import plan_scene, render_planned
    scene = _scene("dgauss.50mm").with_render(spp=1)
    assert plan_scene(scene, measure_costs=False).model == "lens"  # aberrations 1.3 px: no composite
    image = render_planned(scene, threads=2, progress=False)
    assert image.metadata["plan"]["model"] == "lens" and image.metadata["lens_rays"]["from"] == "table"
    # A tolerance below the table's own bound, or the scene or the caller saying so: traced.
    assert "lens_rays" not in render_planned(scene, tolerance_px=0.01, threads=2, progress=False).metadata
    assert "lens_rays" not in render_planned(scene.with_render(lens_rays="traced"), threads=2,
                                             progress=False).metadata
    assert "lens_rays" not in render_planned(scene, lens_rays="traced", threads=2, progress=False).metadata


def test_the_check_weighs_the_light_too(monkeypatch):
    from lenscompare.cameras import lens_ray_table
    model = camera_for(_scene("dgauss.50mm", f_number=8.0, resolution=(64, 42)), "lens")
    taken = lens_ray_table.use_ray_table(model, model.native())
    assert taken["from"] == "table" and abs(taken["weight_sum_over_traced"] - 1) < 0.005
    assert 0 < taken["passing_one_way_only"] < 0.01
    # Tolerances below what the table reaches (0.05 % dimmer, a sliver passing one way): refused.
    for name in ("WEIGHT_SUM_TOLERANCE", "ONE_WAY_TOLERANCE"):
        with monkeypatch.context() as m:
            m.setattr(lens_ray_table, name, 0.0)
            native = model.native()
            assert lens_ray_table.use_ray_table(model, native)["from"] == "traced"
            assert not native.uses_ray_table
