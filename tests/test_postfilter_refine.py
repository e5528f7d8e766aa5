"""The postfilter's refined pinhole pass (lenscompare.postfilter.refine): a few
film samples everywhere, the uniform pass's count where they show an edge."""

from __future__ import annotations

import numpy as np

from lenscompare.cameras import camera_for
from lenscompare.metrics import relative_rmse
from lenscompare.postfilter import depth_buffer_m
from lenscompare.postfilter.edges import DEPTH_JUMP, _neighbour_jumps
from lenscompare.postfilter.refine import BASE_PINHOLE_SPP, CONTRAST_FRACTION, refine_pixels, silhouette_pixels
from lenscompare.reference_scenes import shipped_scene
from lenscompare.render import render
from lenscompare.scene import load_scene


def _step_image(step: float) -> np.ndarray:
    """A grey field of 1.0 with columns 10 onwards ``step`` brighter."""
    pixels = np.ones((12, 20, 3), dtype=np.float32)
    pixels[:, 10:] += step
    return pixels


def test_an_edge_is_redrawn_and_a_flat_field_is_not():
    flat = np.zeros((12, 20), dtype=np.float32)
    none = np.zeros((12, 20), dtype=bool)
    assert not refine_pixels(_step_image(0.0), flat, flat, none).any()
    redraw = refine_pixels(_step_image(0.5), flat, flat, none)
    assert redraw[:, 9:11].all() and not redraw[:, :9].any() and not redraw[:, 11:].any()


def test_a_blur_that_averages_the_pixel_raises_the_threshold():
    flat = np.zeros((12, 20), dtype=np.float32)
    none = np.zeros((12, 20), dtype=bool)
    mean = 1.0 + 0.5 * 0.3  # the step image's mean at step 0.3
    step = 0.3  # 2.6x the threshold without blur; under 3x it, the threshold once the disk covers 9 px
    assert step > CONTRAST_FRACTION * mean
    assert refine_pixels(_step_image(step), flat, flat, none).any()
    area_9_px = np.full((12, 20), 2.0 * np.sqrt(9.0 / np.pi), dtype=np.float32)
    assert not refine_pixels(_step_image(step), flat, area_9_px, none).any()


def test_noise_inside_one_pixel_is_redrawn_with_its_neighbours():
    variance = np.zeros((12, 20), dtype=np.float32)
    variance[5, 5] = 3.0 * 0.1 ** 2  # sd of the mean 0.1 per channel: 10 % of the mean
    redraw = refine_pixels(_step_image(0.0), variance, np.zeros_like(variance), np.zeros((12, 20), dtype=bool))
    assert redraw[4:7, 4:7].all() and redraw.sum() == 9


def test_pixels_drawn_in_full_are_not_redrawn():
    flat = np.zeros((12, 20), dtype=np.float32)
    full = np.zeros((12, 20), dtype=bool)
    full[:, 9] = True
    redraw = refine_pixels(_step_image(0.5), flat, flat, full)
    assert not redraw[:, 9].any() and redraw[:, 10].all()


def test_silhouettes_are_the_edges_modules_depth_steps():
    y, x = np.mgrid[0:30, 0:40].astype(np.float32)
    depth = 2.0 + 0.01 * y + 0.002 * x  # a slope: no step
    depth[10:20, 15:25] = 1.0           # a box in front
    depth[:4] = np.inf                  # sky
    found = silhouette_pixels(depth)
    np.testing.assert_array_equal(found, _neighbour_jumps(depth, np.zeros(depth.shape))[0] > DEPTH_JUMP)
    assert found[10, 20] and found[9, 20] and found[4, 0] and not found[0, 0] and not found[25, 5]


def test_the_refined_pass_comes_close_to_the_uniform_pass_and_ignores_threads():
    scene = load_scene(shipped_scene("showcase")).with_camera(resolution=(120, 80))
    refined = render(scene, model="postfilter", spp=64, threads=1, progress=False)
    uniform = render(scene, model="postfilter", spp=64, threads=1, progress=False, postfilter_uniform_pass=True)
    info = refined.metadata["postfilter"]
    assert info["pinhole_base_spp"] == BASE_PINHOLE_SPP and info["pinhole_spp"] == 16
    assert BASE_PINHOLE_SPP < info["pinhole_mean_spp"] < 16 and 0.0 < info["pinhole_full_fraction"] < 1.0
    # the silhouettes alone would draw fewer: the contrast test redraws edges inside surfaces too
    depth = depth_buffer_m(scene, camera_for(scene, "pinhole"))
    assert info["pinhole_full_fraction"] > silhouette_pixels(depth).mean()
    error = relative_rmse(uniform.pixels, refined.pixels)
    assert 0.0 < error < 0.01, error
    np.testing.assert_array_equal(render(scene, model="postfilter", spp=64, threads=2, progress=False).pixels,
                                  refined.pixels)
