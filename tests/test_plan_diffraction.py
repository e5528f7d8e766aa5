"""The planner's `diffraction` effect: sized as the Airy disk 2.44 λ N_w at
550 nm in pixels, needed above tolerance, and rendered by `--model auto`."""

import json

import numpy as np
import pytest

from lenscompare.diffraction import diffraction_aperture, diffraction_kernel
from lenscompare.image import read_exr
from lenscompare.plan import plan_scene, render_planned
from lenscompare.render import render
from lenscompare.scene import parse_scene

from helpers import camera_scene_text, run_cli, sphere_text

DEPTHS_M = (3.0, 10.0, 100.0)
COLUMNS_PX = (140, 180, 220)  # where the points image, each at the centre of pixel (column, row 120)
D_PRIME_MM = 8.0 * 3000.0 / (3000.0 - 8.0)


def small_pixel_scene_text(f_number=22.0):
    """A phone-like camera: 8 mm lens, 4 µm pixels, focused at 3 m; points at 3-100 m."""
    objects = "".join(sphere_text(((c + 0.5 - 180) * 0.004 * z / D_PRIME_MM, -0.5 * 0.004 * z / D_PRIME_MM, z),
                                  1e-4 * z) for c, z in zip(COLUMNS_PX, DEPTHS_M))
    return camera_scene_text(focal_length_mm=8.0, f_number=f_number, focus_distance=3.0, resolution=(360, 240),
                             film_mm=(1.44, 0.96), spp=64, objects=objects)


def test_f22_with_4um_pixels_needs_diffraction_and_not_defocus():
    scene = parse_scene(small_pixel_scene_text())
    plan = plan_scene(scene, measure_costs=False)
    d = plan.effects["diffraction"]
    n_w = 22.0 * 3000.0 / (3000.0 - 8.0)  # d' / D of the thin lens focused at 3 m
    assert d.unit == "px" and d.magnitude == pytest.approx(2.44 * 0.55e-3 * n_w / 0.004, rel=1e-3)
    assert plan.needed["diffraction"] and not plan.needed["defocus"]
    assert plan.effects["defocus"].magnitude < plan.tolerance_px
    assert plan.model == "pinhole"
    # Wide open the same camera needs no diffraction (Airy disk 0.47 px at f/1.4) but defocus.
    wide = plan_scene(parse_scene(small_pixel_scene_text(f_number=1.4)), measure_costs=False)
    assert wide.effects["diffraction"].magnitude < 0.5 and not wide.needed["diffraction"]
    assert wide.needed["defocus"]


def flux_in_centre_3x3(pixels):
    """For each point, the share of its flux (within 40 px) in the 3x3 block around its pixel."""
    green = pixels[..., 1].astype(float)
    return [green[119:122, c - 1:c + 2].sum() / green[120 - 19:120 + 20, c - 19:c + 20].sum() for c in COLUMNS_PX]


def test_model_auto_renders_the_diffraction_the_plan_asks_for(tmp_path):
    scene = parse_scene(small_pixel_scene_text())
    image = render_planned(scene, threads=2)
    assert image.metadata["plan"]["effects"]["diffraction"]["needed"]
    assert image.metadata["model"] == "pinhole" and "diffraction" in image.metadata
    same = render(scene, model="pinhole", diffraction=True, threads=2)
    np.testing.assert_array_equal(image.pixels, same.pixels)
    # The points are spread as the PSF spreads them: the 3x3 share of their flux
    # drops from nearly all to what the kernel puts there.
    kernel = diffraction_kernel(diffraction_aperture(scene, image.camera))[..., 1]
    r = kernel.shape[0] // 2
    expected = kernel[r - 1:r + 2, r - 1:r + 2].sum() / kernel[r - 19:r + 20, r - 19:r + 20].sum()
    sharp = flux_in_centre_3x3(render(scene, model="pinhole", threads=2).pixels)
    blurred = flux_in_centre_3x3(image.pixels)
    assert min(sharp) > 0.95
    np.testing.assert_allclose(blurred, expected, rtol=0.08)
    # The command line: plan --json says so, render --model auto writes it.
    path = tmp_path / "small_pixels.toml"
    path.write_text(small_pixel_scene_text())
    planned = json.loads(run_cli("plan", path, "--json", "--no-costs").stdout)
    assert planned["effects"]["diffraction"]["needed"] and not planned["effects"]["defocus"]["needed"]
    out = tmp_path / "auto.exr"
    result = run_cli("render", path, "-o", out, "--model", "auto", "--spp", "4")
    assert result.returncode == 0, result.stderr
    assert read_exr(out).metadata["diffraction"]["airy_diameter_px_550nm"] == pytest.approx(
        planned["effects"]["diffraction"]["magnitude"])
