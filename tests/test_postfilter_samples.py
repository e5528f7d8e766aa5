"""Per-pixel pinhole sample counts of the postfilter (lenscompare.postfilter.samples):
fewer film samples where the pixel's blur disk averages its noise."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lenscompare import _native
from lenscompare.cameras import camera_for
from lenscompare.postfilter import MIN_PINHOLE_SPP, depth_buffer_m, pinhole_sample_counts, signed_coc_px
from lenscompare.reference_scenes import shipped_scene
from lenscompare.render import render
from lenscompare.scene import load_scene


def _diameter_px(area_px: float) -> float:
    """The blur diameter whose disk has this area."""
    return 2.0 * math.sqrt(area_px / math.pi)


@pytest.mark.parametrize("spp, area_px, expected", [
    (64, 0.5, 16),   # under a pixel: nothing averages it
    (64, 1.0, 16),
    (64, 2.0, 12),   # ceil(16 / sqrt(2)) = ceil(11.3)
    (64, 3.0, 10),   # ceil(9.24)
    (64, 4.0, 8),
    (64, 5.0, 8),    # ceil(7.16)
    (64, 16.0, 4),
    (64, 50.0, 4),   # ceil(2.26) = 3: the floor
    (8, 1.5, 7),     # n = min(spp, 16) = 8: ceil(8 / sqrt(1.5)) = ceil(6.53)
    (8, 10.0, 4),
    (2, 10.0, 2),    # the floor never exceeds n
])
def test_a_pixel_of_blur_area_a_gets_the_rule_count(spp, area_px, expected):
    coc = np.full((9, 9), _diameter_px(area_px), dtype=np.float32)
    depth = np.full((9, 9), 3.0, dtype=np.float32)  # flat: no discontinuity
    counts = pinhole_sample_counts(coc, depth, spp)
    assert counts.dtype == np.uint32
    assert (counts == expected).all()
    # the sign (in front of / behind the focus) does not matter
    np.testing.assert_array_equal(pinhole_sample_counts(-coc, depth, spp), counts)


def test_pixels_near_a_depth_step_keep_all_their_samples():
    area_px = 16.0  # radius 2.26 px: within 3.26 px of the step keeps 16
    coc = np.full((7, 20), _diameter_px(area_px), dtype=np.float32)
    depth = np.full((7, 20), 3.0, dtype=np.float32)
    depth[:, 10:] = 5.0  # columns 9 and 10 are the step's two sides
    counts = pinhole_sample_counts(coc, depth, 64)
    distance_px = np.minimum(np.abs(np.arange(20) - 9), np.abs(np.arange(20) - 10))
    expected = np.where(distance_px <= math.sqrt(area_px / math.pi) + 1.0, 16, MIN_PINHOLE_SPP)
    np.testing.assert_array_equal(counts, np.broadcast_to(expected, counts.shape))
    # the background (inf) against an object is a step too
    depth[:, 10:] = np.inf
    np.testing.assert_array_equal(pinhole_sample_counts(coc, depth, 64), counts)


def test_the_render_draws_the_rule_counts_and_records_them():
    scene = load_scene(shipped_scene("showcase")).with_camera(resolution=(120, 80), f_number=1.4,
                                                              focus_distance_m=1.9)
    image = render(scene, model="postfilter", spp=64, progress=False, postfilter_per_pixel_spp=True)
    depth = depth_buffer_m(scene, camera_for(scene, "pinhole"))
    counts = pinhole_sample_counts(signed_coc_px(depth, camera_for(scene, "thin")), depth, 64)
    info = image.metadata["postfilter"]
    assert info["pinhole_spp"] == 16
    assert info["pinhole_min_spp"] == int(counts.min()) < 16
    assert info["pinhole_mean_spp"] == pytest.approx(float(counts.mean()))
    assert image.metadata["samples_per_second"] * image.metadata["seconds"] == pytest.approx(counts.sum())


def test_same_image_for_one_and_two_threads_with_fewer_samples():
    scene = load_scene(shipped_scene("showcase")).with_camera(resolution=(120, 80), f_number=1.4,
                                                              focus_distance_m=1.9)
    one = render(scene, model="postfilter", spp=64, seed=3, threads=1, progress=False, postfilter_per_pixel_spp=True)
    two = render(scene, model="postfilter", spp=64, seed=3, threads=2, progress=False, postfilter_per_pixel_spp=True)
    assert one.metadata["postfilter"]["pinhole_min_spp"] < 16
    np.testing.assert_array_equal(one.pixels, two.pixels)



def test_the_uniform_pass_draws_n_everywhere():
    # the default pass is the refined one (tests/test_postfilter_refine.py); the uniform one is asked for
    scene = load_scene(shipped_scene("showcase")).with_camera(resolution=(120, 80), f_number=1.4,
                                                              focus_distance_m=1.9)
    image = render(scene, model="postfilter", spp=64, progress=False, postfilter_uniform_pass=True)
    assert "pinhole_mean_spp" not in image.metadata["postfilter"]
    assert image.metadata["samples_per_second"] * image.metadata["seconds"] == pytest.approx(120 * 80 * 16)
