"""Mitsuba 3 as a second independent reference: the same scenes, exported to
Mitsuba's XML and rendered by the ``mitsuba`` package (3.9.1, variant
``scalar_rgb``) from those files, against equation 5, analytic projections,
an analytic lit patch and the native tracer.

Kept small (Mitsuba's scalar variant traces one ray at a time): about 30 s.
"""

import json

import numpy as np
import pytest

from helpers import run_cli
from lenscompare.errors import InputError
from lenscompare.image import read_exr
from lenscompare.metrics import measure_blur_disk, relative_rmse, ssim
from lenscompare.mitsuba import render_mitsuba, scene_to_mitsuba
from lenscompare.render import render
from lenscompare.scene import load_scene, parse_scene
from test_falloff import analytic_patch, lit_patch
from test_povray_agreement import (BLUR_POINTS, CHECKER_CORNER_SCENE, REFERENCE_SCENES, blur_disk_scene, centroids,
                                   explain, projection_scene)

mitsuba = pytest.importorskip("mitsuba")


def test_thin_lens_blur_disks_match_equation_5(tmp_path):
    """Mitsuba's ``thinlens`` blur disks within 2 % of equation 5 (measured: within 0.5 %), 360 x 240, 256 spp."""
    scene, expected = blur_disk_scene()
    image = render_mitsuba(scene, spp=256)
    rows, failures = [], []
    for (depth_m, _), (x_px, y_px, c_px, source_px) in zip(BLUR_POINTS, expected):
        measured = measure_blur_disk(image.pixels, center_px=(x_px, y_px), window_radius_px=(c_px + source_px) / 2 + 3,
                                     source_diameter_px=source_px).second_moment_diameter_px
        rows.append(f"{depth_m:5.1f} m: eq.5 {c_px:6.2f} px, Mitsuba {measured:6.2f} ({measured / c_px - 1:+.2%})")
        if abs(measured / c_px - 1) > 0.02:
            failures.append(rows[-1])
    message = "\n".join(rows) + f"\n{image.metadata['renderer']}"
    assert not failures, explain(not failures, message, tmp_path, mitsuba=image)


def test_pinhole_projections_match_the_analytic_projection(tmp_path):
    """A tilted, rolled camera (non-default up): Mitsuba's centroids within 0.06 px of the analytic
    projection (256 spp; the spread is sampling noise), mean offset below 0.01 px.

    This is the test of the mirrored camera matrix: with Mitsuba's own (right-handed)
    look-at, every point would land mirrored left to right.
    """
    scene, projected = projection_scene("pinhole")
    image = render_mitsuba(scene, spp=256)
    offset = centroids(image, projected, 3.0) - projected
    worst, mean = np.abs(offset).max(), offset.mean(axis=0)
    message = f"max |Mitsuba - analytic| {worst:.4f} px, mean offset {mean} px"  # measured 0.042, (-0.002, -0.003)
    ok = worst < 0.06 and np.abs(mean).max() < 0.01
    assert ok, explain(ok, message, tmp_path, mitsuba=image)


def test_inverse_square_light_matches_the_analytic_patch():
    """One inverse-square light on a Lambert plane: Mitsuba's point light of intensity pi I and its
    diffuse BSDF (A / pi) give A I cos / d^2, the native shading. 64 independent samples per pixel
    average each pixel's area with noise; the mean ratio is 1 within 2e-4 (measured 2e-5)."""
    scene = lit_patch("inverse_square")
    ratio = render_mitsuba(scene, spp=64).pixels[..., 0] / analytic_patch(scene)
    assert abs(ratio.mean() - 1) < 2e-4 and np.abs(ratio - 1).max() < 0.01


def test_stratified_sampler_is_unbiased_and_less_noisy():
    """The export's ``stratified`` sampler (the native ``jittered``'s construction, timed in
    bench_peers.py): the lit patch's mean ratio to the analytic one is 1 within 2e-4, and its pixels
    scatter less about it than the ``independent`` sampler's at the same 64 spp."""
    scene = lit_patch("inverse_square")
    ratios = {sampler: render_mitsuba(scene, spp=64, sampler=sampler).pixels[..., 0] / analytic_patch(scene)
              for sampler in ("independent", "stratified")}
    assert abs(ratios["stratified"].mean() - 1) < 2e-4
    assert ratios["stratified"].std() < ratios["independent"].std()


def test_stratified_sampler_refuses_a_sample_count_that_is_not_a_square(write_scene, minimal_scene_text):
    """Mitsuba would round 32 up to 36 samples: exit 2 naming --spp, nothing written."""
    with pytest.raises(InputError, match="square sample count, got 32"):
        scene_to_mitsuba(lit_patch("inverse_square"), spp=32, sampler="stratified")
    path = write_scene(minimal_scene_text + 'falloff = "inverse_square"\n')
    result = run_cli("mitsuba", path, "-o", path.parent / "out.exr", "--spp", "32", "--sampler", "stratified")
    assert result.returncode == 2 and "--spp" in result.stderr and "square" in result.stderr
    assert "Traceback" not in result.stderr and not (path.parent / "out.exr").exists()


def test_lit_showcase_agrees_with_native(tmp_path):
    """reference_scenes/lit_showcase.toml (checker floor, diffuse and emissive spheres, two inverse-square
    lights), 180 x 120, 128 spp each: SSIM >= 0.97 (measured 0.993), means within 0.5 % (measured 0.03 %).
    Mitsuba picks one light per sample where native sums both, so its lit pixels are noisier."""
    scene = load_scene(REFERENCE_SCENES / "lit_showcase.toml").with_camera(resolution=(180, 120))
    native, theirs = render(scene, spp=128, threads=2), render_mitsuba(scene, spp=128)
    a, b = native.pixels, theirs.pixels
    similarity = ssim(a, b, data_range=float(a.max() - a.min()))
    mean_ratio = float(b.mean() / a.mean())
    message = f"SSIM {similarity:.4f}, relative RMSE {relative_rmse(a, b):.2%}, mean Mitsuba/native {mean_ratio:.4f}"
    ok = similarity >= 0.97 and abs(mean_ratio - 1) < 0.005
    assert ok, explain(ok, message, tmp_path, native=native, mitsuba=theirs)


def test_checker_cube_boundaries_coincide():
    """The checker cut into two meshes puts the cube boundaries where the native checker has them
    (1 px before the corner, see test_povray_agreement.test_checker_cube_boundaries_coincide)."""
    scene = parse_scene(CHECKER_CORNER_SCENE.replace('[[lights]]\ntype = "point"\nposition = [0.1, 10.0, 0.1]\n'
                                                     'color = [1.0, 1.0, 1.0]',
                                                     '[[lights]]\ntype = "point"\nposition = [0.1, 10.0, 0.1]\n'
                                                     'color = [100.0, 100.0, 100.0]\nfalloff = "inverse_square"'),
                        source="checker_corner.toml")
    white = render_mitsuba(scene, spp=64).pixels[..., 0]
    white = white / white.max()
    assert white[0, 0] == pytest.approx(0.0) and white[-1, 0] == pytest.approx(1.0, abs=0.01)
    x_below, x_above = white[30:].sum(axis=1).mean(), 60 - white[:10].sum(axis=1).mean()
    y_left, y_right = 40 - white[:, :10].sum(axis=0).mean(), white[:, 50:].sum(axis=0).mean()
    assert (x_below, x_above, y_left, y_right) == pytest.approx((29.0, 29.0, 21.0, 21.0), abs=0.05)


def test_emissive_flat_faces_emit_toward_the_camera():
    """flat_field.toml: a one-sided Mitsuba area emitter still shows the wall (radiance 1 everywhere)."""
    scene = load_scene(REFERENCE_SCENES / "flat_field.toml").with_camera(model="pinhole", resolution=(36, 24))
    image = render_mitsuba(scene, spp=4)
    assert np.allclose(image.pixels, 1.0, atol=1e-6)


def test_refusals_name_the_key(write_scene, minimal_scene_text):
    """A lit scene whose light has no falloff, a lens-system model, a checker on a sphere: exit 2, one line."""
    path = write_scene(minimal_scene_text)
    result = run_cli("mitsuba", path, "-o", path.parent / "out.exr")
    assert result.returncode == 2 and "lights[0].falloff" in result.stderr and "inverse_square" in result.stderr
    assert "Traceback" not in result.stderr and not (path.parent / "out.exr").exists()
    lit = minimal_scene_text + 'falloff = "inverse_square"\n'
    result = run_cli("mitsuba", write_scene(lit), "-o", path.parent / "out.exr", "--model", "lens")
    assert result.returncode == 2 and "--model" in result.stderr
    checkered = lit.replace('[materials.glow]\ntype = "emissive"\ncolor = [1.0, 1.0, 1.0]',
                            '[materials.glow]\ntype = "diffuse"\ncolor = [1.0, 1.0, 1.0]\n'
                            'checker = { color = [0.0, 0.0, 0.0], size = 0.1 }')
    with pytest.raises(Exception, match=r"objects\[0\]\.material.*checker"):
        scene_to_mitsuba(parse_scene(checkered, source="s.toml"))


def test_command_writes_the_exr_and_json(tmp_path, minimal_scene_text):
    path = tmp_path / "scene.toml"
    path.write_text(minimal_scene_text + 'falloff = "inverse_square"\n')
    out = tmp_path / "out.exr"
    result = run_cli("mitsuba", path, "-o", out, "--spp", "4", "--model", "pinhole", "--json")
    assert result.returncode == 0, result.stderr
    info = json.loads(result.stdout)
    assert {"model", "spp", "seconds", "samples_per_second", "output"} <= set(info)
    assert info["model"] == "pinhole" and info["spp"] == 4 and info["renderer"].startswith("Mitsuba 3")
    assert read_exr(out).pixels.shape == (24, 36, 3)


LIBLLVM = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"  # Debian 12's libllvm19


@pytest.mark.skipif(not __import__("os").path.exists(LIBLLVM), reason="Debian's libllvm19 is not installed")
def test_llvm_variant_renders_the_same_scene(tmp_path):
    """``--variant llvm_ad_rgb`` with DRJIT_LIBLLVM_PATH naming libLLVM 19: the same picture as scalar_rgb
    (another sampler stream, so compared by SSIM against native, like scalar_rgb)."""
    import os
    import subprocess
    import sys

    scene = REFERENCE_SCENES / "flat_field.toml"
    out = tmp_path / "llvm.exr"
    result = subprocess.run([sys.executable, "-m", "lenscompare", "mitsuba", scene, "-o", out, "--spp", "4",
                             "--model", "pinhole", "--variant", "llvm_ad_rgb", "--json"], capture_output=True,
                            text=True, timeout=600, env={**os.environ, "DRJIT_LIBLLVM_PATH": LIBLLVM})
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout)["renderer"].endswith("llvm_ad_rgb")
    assert np.allclose(read_exr(out).pixels, 1.0, atol=1e-5)  # the flat field's radiance everywhere


def test_unknown_variant_is_exit_2(tmp_path, minimal_scene_text):
    path = tmp_path / "s.toml"
    path.write_text(minimal_scene_text + 'falloff = "inverse_square"\n')
    result = run_cli("mitsuba", path, "-o", tmp_path / "o.exr", "--variant", "cuda_ad_rgb")
    assert result.returncode == 2 and "--variant" in result.stderr
