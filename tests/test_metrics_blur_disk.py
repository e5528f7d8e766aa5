"""Blur-disk measurements against disks rendered here with known diameters."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.signal import fftconvolve
from scipy.special import erf

from lenscompare.metrics import BlurDisk, find_point_sources, measure_blur_disk


def render_disk(shape, center_px, diameter_px, *, supersampling=16):
    """Uniform disk of flux-density 1, each pixel the mean of n x n sub-samples."""
    n = supersampling
    sub = (np.arange(n) + 0.5) / n
    x = (np.arange(shape[1])[:, None] + sub).ravel()
    y = (np.arange(shape[0])[:, None] + sub).ravel()
    r2 = (x[None, :] - center_px[0]) ** 2 + (y[:, None] - center_px[1]) ** 2
    inside = r2 <= (diameter_px / 2) ** 2
    return inside.reshape(shape[0], n, shape[1], n).mean(axis=(1, 3))


def render_gaussian(shape, center_px, sigma_px):
    """Pixel-integrated isotropic Gaussian (exact, via erf)."""
    def axis(n, c):
        edges = (np.arange(n + 1) - c) / (sigma_px * np.sqrt(2))
        return np.diff(0.5 * erf(edges))
    return np.outer(axis(shape[0], center_px[1]), axis(shape[1], center_px[0]))


@pytest.mark.parametrize(
    "diameter_px, center_px",
    [(6.0, (15.37, 14.81)), (15.3, (22.5, 23.02)), (40.0, (35.13, 34.66))],
)
def test_uniform_disk_diameters(diameter_px, center_px):
    size = int(diameter_px) + 30
    disk = measure_blur_disk(render_disk((size, size), center_px, diameter_px))
    assert disk.second_moment_diameter_px == pytest.approx(diameter_px, rel=0.01)
    assert disk.encircled_energy_diameter_px == pytest.approx(diameter_px, rel=0.02)
    assert disk.centroid_px == pytest.approx(center_px, abs=0.01)
    assert disk.flux == pytest.approx(np.pi * diameter_px**2 / 4, rel=1e-3)


def test_rgb_uses_luminance_and_matches_grey():
    grey = render_disk((40, 40), (20.2, 19.6), 12.0)
    rgb = grey[..., None] * np.ones(3)
    assert measure_blur_disk(rgb) == measure_blur_disk(grey)


def test_source_disk_is_corrected_back():
    # Blur disk c = 15.3 px convolved with the image of a source of s = 5 px,
    # both rendered 8x finer than the pixels, then binned to pixels.
    c, s, n, size = 15.3, 5.0, 8, 40
    fine = render_disk((size * n, size * n), (20.3 * n, 19.8 * n), c * n, supersampling=2)
    k = int(s * n) + 4
    kernel = render_disk((k, k), (k / 2, k / 2), s * n, supersampling=2)
    blurred = fftconvolve(fine, kernel / kernel.sum(), mode="same")
    image = blurred.reshape(size, n, size, n).mean(axis=(1, 3))

    corrected = measure_blur_disk(image, source_diameter_px=s)
    uncorrected = measure_blur_disk(image)
    assert corrected.second_moment_diameter_px == pytest.approx(c, rel=0.01)
    assert uncorrected.second_moment_diameter_px == pytest.approx(np.hypot(c, s), rel=0.01)
    # The half-energy circle lies inside the blurred edge: s < 0.3 c leaves it alone.
    assert corrected.encircled_energy_diameter_px == pytest.approx(c, rel=0.02)


def test_more_blur_gives_larger_diameters():
    disks = [measure_blur_disk(render_disk((60, 60), (30.4, 29.9), c)) for c in (3, 6, 12, 24, 48)]
    for smaller, larger in zip(disks, disks[1:]):
        assert larger.second_moment_diameter_px > smaller.second_moment_diameter_px
        assert larger.encircled_energy_diameter_px > smaller.encircled_energy_diameter_px


@settings(max_examples=25, deadline=None)
@given(st.floats(10, 11), st.floats(10, 11), st.floats(1.0, 3.0))
def test_centroid_of_symmetric_blob(cx, cy, sigma):
    disk = measure_blur_disk(render_gaussian((21, 21), (cx, cy), sigma))
    assert disk.centroid_px == pytest.approx((cx, cy), abs=0.01)


def test_gaussian_diameters_tell_a_core_from_a_disk():
    # Notes: a Gaussian of standard deviation sigma gives 4 sigma (second
    # moment) against 2 sqrt(2) sqrt(2 ln 2) sigma = 3.33 sigma (encircled energy).
    sigma = 4.0
    disk = measure_blur_disk(render_gaussian((61, 61), (30.3, 30.6), sigma))
    assert disk.second_moment_diameter_px == pytest.approx(4 * sigma, rel=0.01)
    expected_ee = 4 * np.sqrt(np.log(2)) * sigma
    assert disk.encircled_energy_diameter_px == pytest.approx(expected_ee, rel=0.01)


def test_faint_halo_moves_second_moment_not_encircled_energy():
    shape, center = (120, 120), (60.2, 59.7)
    image = render_disk(shape, center, 12.0)
    halo = render_disk(shape, center, 100.0) - render_disk(shape, center, 80.0)
    image_with_halo = image + halo * 0.01 * image.sum() / halo.sum()  # 1 % of the flux
    clean, haloed = measure_blur_disk(image), measure_blur_disk(image_with_halo)
    assert haloed.second_moment_diameter_px > 1.3 * clean.second_moment_diameter_px
    assert haloed.encircled_energy_diameter_px == pytest.approx(
        clean.encircled_energy_diameter_px, rel=0.01
    )


def test_window_isolates_one_source_and_follows_it():
    alone = render_disk((60, 100), (25.3, 30.1), 10.0)
    both = alone + render_disk((60, 100), (75.0, 30.0), 20.0)
    expected = measure_blur_disk(alone)
    placed = measure_blur_disk(both, center_px=(25.0, 30.0), window_radius_px=15.0)
    assert placed.centroid_px == pytest.approx(expected.centroid_px, abs=1e-9)
    assert placed.second_moment_diameter_px == pytest.approx(
        expected.second_moment_diameter_px, rel=1e-9
    )
    # A faint second source pulls the whole-image centroid 4 px off;
    # the window follows the bright one.
    faint = alone + 0.025 * render_disk((60, 100), (75.0, 30.0), 20.0)
    followed = measure_blur_disk(faint, window_radius_px=15.0)
    assert followed.centroid_px == pytest.approx(expected.centroid_px, abs=1e-9)


def test_background_is_subtracted():
    image = render_disk((40, 40), (20.2, 19.6), 12.0)
    shifted = measure_blur_disk(image + 0.25, background=0.25)
    assert shifted.second_moment_diameter_px == pytest.approx(
        measure_blur_disk(image).second_moment_diameter_px, rel=1e-9
    )


def test_find_point_sources_separates_and_sorts():
    shape = (80, 160)
    truth = [((120.4, 20.7), 14.0), ((30.2, 50.3), 8.0), ((80.6, 40.1), 24.0)]
    image = sum(render_disk(shape, center, c) / c**2 for center, c in truth)  # equal flux
    disks = find_point_sources(image)
    assert len(disks) == 3 and all(isinstance(d, BlurDisk) for d in disks)
    assert [d.centroid_px[0] for d in disks] == sorted(d.centroid_px[0] for d in disks)
    for disk, (center, c) in zip(disks, sorted(truth)):
        assert disk.centroid_px == pytest.approx(center, abs=0.01)
        assert disk.second_moment_diameter_px == pytest.approx(c, rel=0.01)
        assert disk.encircled_energy_diameter_px == pytest.approx(c, rel=0.02)


def test_find_point_sources_merges_close_regions():
    image = np.zeros((20, 30))
    image[8:11, 5:8] = 1.0
    image[8:11, 10:13] = 1.0  # two px apart
    assert len(find_point_sources(image, min_separation_px=4.0)) == 1
    assert len(find_point_sources(image, min_separation_px=1.0)) == 2


def test_find_point_sources_on_empty_image_is_empty():
    assert find_point_sources(np.zeros((10, 10))) == []


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"center_px": (5, 5)}, "window_radius_px"),
        ({"window_radius_px": -1.0}, "window_radius_px"),
        ({"source_diameter_px": np.nan}, "source_diameter_px"),
        ({"background": 2.0}, "no positive flux"),
    ],
)
def test_bad_arguments_raise_value_error(kwargs, match):
    with pytest.raises(ValueError, match=match):
        measure_blur_disk(render_disk((20, 20), (10, 10), 6.0), **kwargs)


@pytest.mark.parametrize("image", [np.zeros((4, 4, 2)), np.zeros((0, 3)), np.full((3, 3), np.inf)])
def test_bad_images_raise_value_error(image):
    with pytest.raises(ValueError, match="image"):
        measure_blur_disk(image)
