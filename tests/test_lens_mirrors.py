"""The lens system's mirrored rays (native render_mirrored.h): a pixel and its
mirror images across the film's centre lines take one traced set of samples,
reflected, since a lens of round surfaces is symmetric under those reflections.

What must hold: the lens is only mirrored where it is symmetric (a bladed stop
of an odd polygon has one mirror axis or none); a pixel's value does not depend
on which rows a call renders with it, nor on the thread count; every pixel is
rendered once, odd sizes included (their middle row and column are their own
mirror images); and the mirrored render estimates the same image as the one
that traces every sample (differences within the two renders' own noise).
Also how they are asked for: the scene key, the command-line flag, the
environment variable, and --model auto, which mirrors a lens-system plan
unless the scene measures distortion or vignetting.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from lenscompare import _native
from lenscompare.cameras import camera_for
from lenscompare.native_scene import build_native_scene
from lenscompare.render import SAMPLER_CODES
from lenscompare.render_spectral import make_spectral
from lenscompare.scene import load_scene

ROOT = Path(__file__).resolve().parent.parent
PEERS = ROOT / "bench" / "scenes" / "peers_lit.toml"
DISPERSIVE = ROOT / "tests" / "data" / "lenses" / "dgauss_abbe.dat"


def lens_scene(*, resolution=(64, 42), **camera):
    return load_scene(PEERS).with_camera(lens="dgauss.50mm", f_number=None, resolution=resolution,
                                         focal_length_mm=None, **camera)


def with_mirrors_on(camera):
    """The native lens system with its mirrors on (render's lens_mirrors)."""
    camera.mirror_axes = camera.symmetric_mirror_axes
    return camera


def render_bands(scene, camera, bands, *, spp=8, threads=2, sampler="jittered", mirror_rows=False, counts=None,
                 seed=3, native_scene=None):
    """The image from native render calls over row bands [(begin, end), ...]."""
    width, height = scene.camera.resolution
    native_scene = build_native_scene(scene) if native_scene is None else native_scene
    pixels = np.zeros((height, width, 3), dtype=np.float32)
    variance = np.zeros((height, width), dtype=np.float32)
    samples = 0
    for begin, end in bands:
        if counts is None:
            drawn, _ = _native.render_rows(native_scene, camera, spp, SAMPLER_CODES[sampler], seed, threads, begin,
                                           end, pixels, variance, mirror_rows=mirror_rows)
        else:
            drawn, _ = _native.render_rows_adaptive(native_scene, camera, counts, 0, SAMPLER_CODES[sampler], seed,
                                                    threads, begin, end, pixels, variance, mirror_rows=mirror_rows)
        samples += drawn
    return pixels, variance, samples


@pytest.mark.parametrize("blades, rotation_deg, axes", [
    (0, 0.0, 3),    # round: both mirrors
    (6, 0.0, 3),    # hexagon, a vertex up: symmetric about both axes
    (5, 0.0, 1),    # pentagon, a vertex up: about the vertical axis only (x -> -x)
    (5, 90.0, 2),   # pentagon, a vertex to the side: about the horizontal axis only
    (5, 10.0, 0),   # turned off both
])
def test_mirrors_only_where_the_stop_is_symmetric(blades, rotation_deg, axes):
    scene = lens_scene(aperture_blades=blades, aperture_rotation_deg=rotation_deg)
    camera = camera_for(scene, "lens").native()
    assert camera.mirror_axes == 0  # off unless asked for
    assert camera.symmetric_mirror_axes == axes


@pytest.mark.parametrize("resolution", [(64, 42), (63, 41)])
@pytest.mark.parametrize("blades, rotation_deg", [(0, 0.0), (5, 0.0), (5, 90.0)])
def test_pixel_independent_of_the_rows_rendered_with_it(resolution, blades, rotation_deg):
    scene = lens_scene(resolution=resolution, aperture_blades=blades, aperture_rotation_deg=rotation_deg)
    camera = with_mirrors_on(camera_for(scene, "lens").native())
    width, height = resolution
    whole, _, whole_samples = render_bands(scene, camera, [(0, height)], threads=2)
    half = (height + 1) // 2
    mirrored, _, mirrored_samples = render_bands(scene, camera, [(0, 7), (7, half)], threads=1, mirror_rows=True)
    uneven, _, uneven_samples = render_bands(scene, camera, [(0, 5), (5, 30), (30, height)], threads=2)
    # bands of the bottom half (one across the middle), their mirror rows in the top half
    lower, _, lower_samples = render_bands(scene, camera, [(height // 2 - 2, height // 2 + 3), (height // 2 + 3, height)],
                                           mirror_rows=True)
    # every pixel once: samples drawn, and no pixel left black by a skipped image
    assert whole_samples == mirrored_samples == uneven_samples == lower_samples == width * height * 8
    assert (whole.sum(axis=2) > 0).mean() > 0.99
    np.testing.assert_array_equal(whole, mirrored)
    np.testing.assert_array_equal(whole, uneven)
    np.testing.assert_array_equal(whole, lower)


@pytest.mark.parametrize("model", ["pinhole", "lens"])
def test_mirror_rows_of_any_band_without_mirrored_rays(model):
    """render_rows(mirror_rows=True) renders a band's mirror rows whichever half
    it lies in, for cameras that trace every sample too."""
    scene = lens_scene(resolution=(40, 27))
    camera = camera_for(scene, model).native()
    whole, _, whole_samples = render_bands(scene, camera, [(0, 27)])
    banded, _, banded_samples = render_bands(scene, camera, [(20, 27), (11, 20)], mirror_rows=True)
    assert whole_samples == banded_samples == 40 * 27 * 8
    np.testing.assert_array_equal(whole, banded)


def test_adaptive_counts_mirror_consistently():
    """Mirror images with different sample counts draw their own counts."""
    scene = lens_scene(resolution=(63, 41))
    camera = with_mirrors_on(camera_for(scene, "lens").native())
    counts = np.random.default_rng(1).integers(0, 12, size=(41, 63)).astype(np.uint32)
    whole, _, whole_samples = render_bands(scene, camera, [(0, 41)], counts=counts, sampler="sobol")
    banded, _, _ = render_bands(scene, camera, [(0, 9), (9, 21)], counts=counts, sampler="sobol",
                                mirror_rows=True, threads=1)
    assert whole_samples == int(counts.sum())
    np.testing.assert_array_equal(whole, banded)
    assert (whole.sum(axis=2)[counts == 0] == 0).all()
    # a pixel whose counts equal its canonical pixel's takes the same samples as a uniform render
    uniform_counts = np.full((41, 63), 8, dtype=np.uint32)
    uniform, _, _ = render_bands(scene, camera, [(0, 41)], counts=uniform_counts, sampler="sobol")
    plain, _, _ = render_bands(scene, camera, [(0, 41)], sampler="sobol")
    np.testing.assert_array_equal(uniform, plain)


@pytest.mark.parametrize("blades, rotation_deg", [(0, 0.0), (5, 0.0)])
def test_mirrored_render_estimates_the_traced_image(blades, rotation_deg):
    """Mirrors on and off: the same image within the noise. The mirrored
    render differs from a traced one as much as two traced ones with other
    seeds differ (RMS ratio near 1), and not in the mean."""
    scene = lens_scene(resolution=(48, 32), aperture_blades=blades, aperture_rotation_deg=rotation_deg)
    mirrored_camera = with_mirrors_on(camera_for(scene, "lens").native())
    traced_camera = camera_for(scene, "lens").native()
    assert mirrored_camera.mirror_axes != 0 and traced_camera.mirror_axes == 0
    mirrored, _, _ = render_bands(scene, mirrored_camera, [(0, 32)], spp=64, seed=3)
    traced, _, _ = render_bands(scene, traced_camera, [(0, 32)], spp=64, seed=4)
    traced_again, _, _ = render_bands(scene, traced_camera, [(0, 32)], spp=64, seed=5)
    assert np.isfinite(mirrored).all()
    rms_mirrored = np.sqrt(np.mean((mirrored - traced) ** 2))
    rms_traced = np.sqrt(np.mean((traced_again - traced) ** 2))
    assert rms_traced > 0.0
    assert 0.8 < rms_mirrored / rms_traced < 1.25, (rms_mirrored, rms_traced)
    assert abs(mirrored.mean() / traced.mean() - 1.0) < 0.01


def dispersive_spectral(traced, *, resolution=(63, 41), with_mirrors=True):
    scene = load_scene(PEERS).with_camera(lens=str(DISPERSIVE), f_number=None, resolution=resolution,
                                          focal_length_mm=None)
    camera = camera_for(scene, "lens")
    native_scene, native_camera = build_native_scene(scene), camera.native()
    if with_mirrors:
        with_mirrors_on(native_camera)
    assert make_spectral(native_scene, native_camera, scene, camera, traced_wavelengths=traced)["camera_disperses"]
    return scene, native_scene, native_camera


@pytest.mark.parametrize("traced", [1, 2, 4])
def test_spectral_pixel_independent_of_the_rows_rendered_with_it(traced):
    """A dispersive lens's mirrored rays at each traced wavelength."""
    scene, native_scene, camera = dispersive_spectral(traced)
    whole, _, samples = render_bands(scene, camera, [(0, 41)], native_scene=native_scene)
    banded, _, _ = render_bands(scene, camera, [(0, 6), (6, 21)], mirror_rows=True, threads=1,
                                native_scene=native_scene)
    assert samples == 63 * 41 * 8
    assert np.isfinite(whole).all() and (whole.sum(axis=2) > 0).mean() > 0.99
    np.testing.assert_array_equal(whole, banded)


def test_spectral_mirrored_render_estimates_the_traced_image():
    scene, native_scene, mirrored_camera = dispersive_spectral(2, resolution=(48, 32))
    _, traced_scene, traced_camera = dispersive_spectral(2, resolution=(48, 32), with_mirrors=False)
    mirrored, _, _ = render_bands(scene, mirrored_camera, [(0, 32)], spp=64, seed=3, native_scene=native_scene)
    traced, _, _ = render_bands(scene, traced_camera, [(0, 32)], spp=64, seed=4, native_scene=traced_scene)
    traced_again, _, _ = render_bands(scene, traced_camera, [(0, 32)], spp=64, seed=5, native_scene=traced_scene)
    rms_mirrored = np.sqrt(np.mean((mirrored - traced) ** 2))
    rms_traced = np.sqrt(np.mean((traced_again - traced) ** 2))
    assert 0.8 < rms_mirrored / rms_traced < 1.25, (rms_mirrored, rms_traced)
    assert abs(mirrored.mean() / traced.mean() - 1.0) < 0.01


def test_render_option_and_metadata():
    """render(lens_mirrors=True) mirrors and says so; by default nothing is mirrored."""
    from lenscompare.render import render
    scene = lens_scene(resolution=(32, 22))
    on = render(scene, model="lens", spp=4, sampler="jittered", seed=3, threads=1, progress=False, lens_mirrors=True)
    off = render(scene, model="lens", spp=4, sampler="jittered", seed=3, threads=1, progress=False)
    assert on.metadata["lens_mirror_axes"] == 3 and "lens_mirror_axes" not in off.metadata
    assert not np.array_equal(np.asarray(on.pixels), np.asarray(off.pixels))
    # the mirrored image is exactly what the native bands give with the mirrors set
    camera = with_mirrors_on(camera_for(scene, "lens").native())
    np.testing.assert_array_equal(np.asarray(on.pixels), render_bands(scene, camera, [(0, 22)], spp=4)[0])


def test_scene_key_and_command_line_flag(tmp_path):
    """[render] lens_mirrors and render --lens-mirrors turn the mirrors on; an
    explicit false (scene or caller) keeps them off; a non-boolean is refused
    naming the key."""
    import json
    import subprocess
    import sys

    from lenscompare.errors import InputError
    from lenscompare.render import render
    text = PEERS.read_text().replace("[render]", "[render]\nlens_mirrors = true", 1)
    path = tmp_path / "mirrored.toml"
    path.write_text(text)
    scene = load_scene(path).with_camera(lens="dgauss.50mm", f_number=None, resolution=(32, 22), focal_length_mm=None)
    assert scene.render.lens_mirrors is True
    options = dict(model="lens", spp=2, seed=3, threads=1, progress=False)
    assert render(scene, **options).metadata["lens_mirror_axes"] == 3
    assert "lens_mirror_axes" not in render(scene, lens_mirrors=False, **options).metadata
    path.write_text(PEERS.read_text().replace("[render]", '[render]\nlens_mirrors = "yes"', 1))
    with pytest.raises(InputError, match="render.lens_mirrors"):
        load_scene(path)
    # The command line: the flag on a scene that does not set the key.
    plain = tmp_path / "plain.toml"
    plain.write_text(PEERS.read_text().replace("resolution = [240, 160]", "resolution = [48, 32]", 1)
                     .replace("f_number = 2.0", "f_number = 4.0", 1))  # the Double Gauss opens to f/2.03
    out = tmp_path / "out.exr"
    base = [sys.executable, "-m", "lenscompare", "render", str(plain), "-o", str(out), "--model", "lens",
            "--lens", "dgauss.50mm", "--spp", "1", "--threads", "1", "--json"]
    for flag, axes in (([], None), (["--lens-mirrors"], 3)):
        done = subprocess.run(base + flag, capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        assert json.loads(done.stdout).get("lens_mirror_axes") == axes


def test_model_auto_mirrors_a_lens_system_plan_unless_told_or_measuring_mirror_images():
    from lenscompare.plan import plan_scene, render_planned
    scene = load_scene(ROOT / "lenscompare" / "reference_scenes" / "showcase.toml").with_camera(
        lens="dgauss.50mm", f_number=None, resolution=(240, 160), focal_length_mm=None).with_render(spp=1)
    assert plan_scene(scene, measure_costs=False).model == "lens"  # aberrations 1.3 px: no composite
    options = dict(threads=1, progress=False)
    assert render_planned(scene, **options).metadata["lens_mirror_axes"] == 3
    # told so by the scene or by the caller: traced
    assert "lens_mirror_axes" not in render_planned(scene.with_render(lens_mirrors=False), **options).metadata
    assert "lens_mirror_axes" not in render_planned(scene, lens_mirrors=False, **options).metadata
    for measure in ("vignetting", "distortion"):
        measuring = dataclasses.replace(scene, measure=("similarity", measure))
        assert "lens_mirror_axes" not in render_planned(measuring, **options).metadata
    # blur disks gain from the mirrors (bench_lens_mirrors.py)
    measuring = dataclasses.replace(scene, measure=("blur_disks",))
    assert render_planned(measuring, **options).metadata["lens_mirror_axes"] == 3


def test_plan_times_the_lens_system_as_model_auto_renders_it():
    """The plan's predicted times hold the traced lens system and, as
    ``lens_auto``, the one --model auto renders; the time saved is against it."""
    from lenscompare.plan import auto_lens_options, plan_scene
    scene = load_scene(ROOT / "lenscompare" / "reference_scenes" / "showcase.toml").with_camera(
        lens="dgauss.50mm", f_number=None, resolution=(240, 160), focal_length_mm=None).with_render(spp=1)
    assert auto_lens_options(scene, tolerance_px=0.5) == {"lens_rays": "table", "lens_mirrors": True}
    assert auto_lens_options(scene, tolerance_px=0.01, lens_mirrors=False) == {}
    data = plan_scene(scene, threads=1).to_json()
    assert data["model"] == "lens" and {"lens", "lens_auto"} <= set(data["predicted_seconds"])
    seconds = data["predicted_seconds"]
    assert data["time_saved_seconds_vs_lens"] == pytest.approx(seconds["lens"] - seconds["lens_auto"])
    # Another plan: no lens_auto to time.
    thin = plan_scene(scene.with_camera(lens=None, focal_length_mm=50.0, f_number=2.8), threads=1).to_json()
    assert thin["model"] != "lens" and "lens_auto" not in thin["predicted_seconds"]


def test_an_explicit_false_holds_over_the_environment_variable(monkeypatch):
    """LENSCOMPARE_LENS_MIRRORS=1 mirrors every lens system whose render does
    not say; lens_mirrors=False (or the scene's false) still traces every sample."""
    from lenscompare.render import render
    monkeypatch.setenv("LENSCOMPARE_LENS_MIRRORS", "1")
    scene = lens_scene(resolution=(32, 22))
    options = dict(model="lens", spp=2, seed=3, threads=1, progress=False)
    assert render(scene, **options).metadata["lens_mirror_axes"] == 3
    assert "lens_mirror_axes" not in render(scene, lens_mirrors=False, **options).metadata
    assert "lens_mirror_axes" not in render(scene.with_render(lens_mirrors=False), **options).metadata
