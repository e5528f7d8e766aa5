"""Distortion metrics on dot grids rendered here and warped by known k1, k2."""

import numpy as np
import pytest

from lenscompare.metrics import (
    RadialDistortionFit,
    distortion_percent,
    dot_centroids,
    fit_radial_distortion,
    match_points,
)

SHAPE = (200, 300)  # H, W
CENTER = np.array([150.37, 99.71])  # the optical axis, a little off (W / 2, H / 2)
NORMALIZE = float(np.hypot(150.0, 100.0))  # half-diagonal


def ideal_grid(pitch_px=20.0):
    """Dot centres of an undistorted grid, symmetric about the image centre."""
    offsets_x = np.arange(-6, 7) * pitch_px
    offsets_y = np.arange(-4, 5) * pitch_px
    gx, gy = np.meshgrid(offsets_x, offsets_y)
    return CENTER + np.column_stack([gx.ravel(), gy.ravel()])


def warp(points_px, k1, k2=0.0):
    """Radial model r_d = r_u (1 + k1 rho^2 + k2 rho^4) about CENTER."""
    offset = points_px - CENTER
    rho2 = np.sum(offset**2, axis=1) / NORMALIZE**2
    return CENTER + offset * (1 + k1 * rho2 + k2 * rho2**2)[:, None]


def render_dots(centers_px, diameter_px=6.0, supersampling=8):
    """Bright disks (pixel means of n x n sub-samples) on black."""
    n = supersampling
    image = np.zeros(SHAPE)
    sub = (np.arange(n) + 0.5) / n
    r = diameter_px / 2
    for cx, cy in centers_px:
        x0, y0 = int(cx - r) - 1, int(cy - r) - 1
        x1, y1 = int(cx + r) + 2, int(cy + r) + 2
        x = (np.arange(x0, x1)[:, None] + sub).ravel()
        y = (np.arange(y0, y1)[:, None] + sub).ravel()
        inside = (x[None, :] - cx) ** 2 + (y[:, None] - cy) ** 2 <= r * r
        image[y0:y1, x0:x1] += inside.reshape(y1 - y0, n, x1 - x0, n).mean(axis=(1, 3))
    return image


def measure_grid(k1, k2=0.0):
    ideal = ideal_grid()
    measured = dot_centroids(render_dots(warp(ideal, k1, k2)))
    i_measured, i_ideal = match_points(measured, ideal, max_distance_px=8.0)
    assert len(i_ideal) == len(ideal)
    return measured[i_measured], ideal[i_ideal]


def test_dot_centroids_are_accurate_raster_positions():
    truth = warp(ideal_grid(), -0.08)
    found = dot_centroids(render_dots(truth, supersampling=16))
    i_found, i_truth = match_points(found, truth, max_distance_px=5.0)
    assert len(i_truth) == len(truth)
    assert np.abs(found[i_found] - truth[i_truth]).max() < 0.01  # measured: 0.007 px


def test_dot_centroid_of_one_pixel_is_its_centre():
    image = np.zeros((5, 7))
    image[1, 4] = 1.0  # row 1, column 4
    np.testing.assert_array_equal(dot_centroids(image, threshold=0.5), [[4.5, 1.5]])
    np.testing.assert_array_equal(dot_centroids(np.stack([image] * 3, axis=-1)), [[4.5, 1.5]])


def test_undistorted_grid_reads_zero_percent():
    measured, ideal = measure_grid(0.0)
    result = distortion_percent(measured, ideal, center_px=CENTER)
    off_center = result.ideal_radius_px > 0
    assert np.isnan(result.percent[~off_center]).all()  # the centre dot
    assert np.abs(result.percent[off_center]).max() < 0.05  # centroid noise only


def test_distortion_percent_is_the_model_value():
    ideal = ideal_grid()
    result = distortion_percent(warp(ideal, -0.05, 0.01), ideal, center_px=CENTER)
    rho2 = (result.ideal_radius_px / NORMALIZE) ** 2
    expected = 100 * (-0.05 * rho2 + 0.01 * rho2**2)
    off_center = result.ideal_radius_px > 0
    np.testing.assert_allclose(result.percent[off_center], expected[off_center], atol=1e-9)
    assert (result.percent[off_center] < 0).all()  # barrel


@pytest.mark.parametrize("k1, k2", [(-0.08, 0.0), (0.05, 0.0), (-0.1, 0.04)])
def test_fit_recovers_known_coefficients_from_a_rendered_grid(k1, k2):
    measured, ideal = measure_grid(k1, k2)
    fit = fit_radial_distortion(measured, ideal, center_px=CENTER, normalize_radius_px=NORMALIZE)
    assert isinstance(fit, RadialDistortionFit)
    assert fit.k1 == pytest.approx(k1, abs=1e-3)
    assert fit.k2 == pytest.approx(k2, abs=1e-3)
    assert fit.rms_residual_px < 0.01


def test_fit_is_exact_on_exact_points_and_ignores_tangential_error():
    ideal = ideal_grid()
    measured = warp(ideal, -0.07, 0.02)
    fit = fit_radial_distortion(measured, ideal, center_px=CENTER, normalize_radius_px=NORMALIZE)
    assert (fit.k1, fit.k2) == pytest.approx((-0.07, 0.02), abs=1e-12)
    assert fit.rms_residual_px < 1e-9
    # Moving every point 0.5 px at right angles to its radius changes |r|
    # but not the radial component the fit uses.
    offset = ideal - CENTER
    radius = np.hypot(*offset.T)[:, None]
    perpendicular = offset[:, ::-1] * [-1, 1]
    tangent = np.divide(perpendicular, radius, out=np.zeros_like(offset), where=radius > 0)
    sheared = fit_radial_distortion(
        measured + 0.5 * tangent, ideal, center_px=CENTER, normalize_radius_px=NORMALIZE
    )
    assert (sheared.k1, sheared.k2) == pytest.approx((-0.07, 0.02), abs=1e-12)


def test_match_points_is_one_to_one_and_skips_strays():
    ideal = ideal_grid()
    rng = np.random.default_rng(1)
    order = rng.permutation(len(ideal))[:-3]  # shuffle and lose three dots
    measured = np.vstack([ideal[order] + rng.normal(0, 0.5, (len(order), 2)), [[2.0, 2.0]]])
    i_measured, i_ideal = match_points(measured, ideal, max_distance_px=5.0)
    assert len(i_ideal) == len(order)
    np.testing.assert_array_equal(i_ideal, np.sort(order))
    np.testing.assert_array_equal(order[i_measured], i_ideal)


def test_match_points_respects_max_distance():
    i_measured, i_ideal = match_points([[0.0, 0.0]], [[3.0, 4.0]], max_distance_px=4.9)
    assert len(i_measured) == len(i_ideal) == 0
    assert match_points([[0.0, 0.0]], [[3.0, 4.0]], max_distance_px=5.0)[1].tolist() == [0]


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: distortion_percent([[1, 2]], [[1, 2], [3, 4]], center_px=(0, 0)), "same shape"),
        (lambda: distortion_percent([[1, 2]], [[1, 2]], center_px=(0,)), "center_px"),
        (lambda: match_points([1, 2], [[1, 2]], max_distance_px=1), r"\(N, 2\)"),
        (lambda: match_points([[1, 2]], [[1, 2]], max_distance_px=0), "max_distance_px"),
        (
            lambda: fit_radial_distortion(
                [[1, 0]], [[1, 0]], center_px=(0, 0), normalize_radius_px=1
            ),
            "two or more distinct radii",
        ),
        (
            lambda: fit_radial_distortion(
                [[1, 0], [2, 0]], [[1, 0], [2, 0]], center_px=(0, 0), normalize_radius_px=-1
            ),
            "normalize_radius_px",
        ),
    ],
)
def test_bad_arguments_raise_value_error(call, match):
    with pytest.raises(ValueError, match=match):
        call()
