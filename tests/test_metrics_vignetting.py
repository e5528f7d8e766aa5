"""Relative illumination of synthetic flat fields with a known falloff."""

import numpy as np
import pytest

from lenscompare.metrics import relative_illumination, relative_illumination_at


def cos4_flat_field(shape, focal_px, center_px=None):
    """Natural vignetting cos^4(theta), cos(theta) = f / sqrt(f^2 + r^2), at pixel centres."""
    h, w = shape
    cx, cy = (w / 2, h / 2) if center_px is None else center_px
    rows, cols = np.indices(shape)
    r2 = (cols + 0.5 - cx) ** 2 + (rows + 0.5 - cy) ** 2
    return (focal_px**2 / (focal_px**2 + r2)) ** 2


def cos4(radius_px, focal_px):
    return (focal_px**2 / (focal_px**2 + np.asarray(radius_px) ** 2)) ** 2


@pytest.mark.parametrize("focal_px", [150.0, 300.0])
def test_cos4_falloff_is_recovered(focal_px):
    image = cos4_flat_field((240, 360), focal_px)
    radius_px, illumination = relative_illumination(image)
    assert illumination[0] == 1.0
    np.testing.assert_allclose(illumination, cos4(radius_px, focal_px), rtol=0.005)
    assert np.all(np.diff(illumination) < 0)


def test_rgb_and_off_centre_axis():
    center = (150.0, 100.0)
    grey = cos4_flat_field((240, 360), 200.0, center)
    rgb = grey[..., None] * [0.5, 1.0, 2.0]  # luminance = grey * 1.0718
    radius_px, illumination = relative_illumination(
        rgb, center_px=center, n_bins=20, max_radius_px=150.0
    )
    assert 0 < radius_px[0] < 150.0 / 20  # inside the first bin
    np.testing.assert_allclose(illumination, cos4(radius_px, 200.0), rtol=0.005)


def test_uniform_image_gives_exactly_one():
    _, illumination = relative_illumination(np.full((100, 150, 3), 0.5))
    assert np.all(illumination == 1.0)
    _, illumination = relative_illumination(np.full((101, 37), 0.3), n_bins=10)
    np.testing.assert_allclose(illumination, 1.0, rtol=1e-14)


def test_brightness_does_not_matter():
    image = cos4_flat_field((120, 180), 100.0)
    _, one = relative_illumination(image)
    _, bright = relative_illumination(7.5 * image)
    np.testing.assert_allclose(bright, one, rtol=1e-12)


def test_bins_without_pixels_are_nan():
    _, illumination = relative_illumination(np.ones((20, 20)), n_bins=5, max_radius_px=30.0)
    assert np.isnan(illumination[-1]) and np.all(illumination[:3] == 1.0)


def test_relative_illumination_at_interpolates():
    image = cos4_flat_field((240, 360), 200.0)
    radii = np.array([10.0, 55.5, 120.0, 200.0])
    interpolated = relative_illumination_at(image, radii)
    np.testing.assert_allclose(interpolated, cos4(radii, 200.0), rtol=0.005)
    assert isinstance(relative_illumination_at(image, 50.0), float)
    assert relative_illumination_at(np.ones((30, 30)), 0.0, n_bins=8) == 1.0


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"n_bins": 0}, "n_bins"),
        ({"n_bins": 2.5}, "n_bins"),
        ({"max_radius_px": -5.0}, "max_radius_px"),
        ({"center_px": (1.0, np.nan)}, "center_px"),
    ],
)
def test_bad_arguments_raise_value_error(kwargs, match):
    with pytest.raises(ValueError, match=match):
        relative_illumination(np.ones((10, 10)), **kwargs)


def test_dark_centre_and_out_of_range_radius_raise_value_error():
    with pytest.raises(ValueError, match="central bin"):
        relative_illumination(np.zeros((10, 10)))
    with pytest.raises(ValueError, match="radius_px"):
        relative_illumination_at(np.ones((10, 10)), 100.0, n_bins=4)
    with pytest.raises(ValueError, match="radius_px"):
        relative_illumination_at(np.ones((10, 10)), -1.0, n_bins=4)
    # Bins narrower than the distance to the nearest pixel centre leave the first one empty.
    with pytest.raises(ValueError, match="central bin"):
        relative_illumination(np.ones((10, 10)), n_bins=32)
