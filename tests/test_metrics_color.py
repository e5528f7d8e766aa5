"""Per-channel colour metrics (lenscompare.metrics.color) on real renders.

The lateral- and longitudinal-colour images here are built from real RGB
renders (the shipped dot grid and blur disks) by changing one channel
analytically: a radial magnification about the centre (dots move out by k r,
exactly, for a continuous image) and a convolution with a disk kernel
(second moments add under convolution, exactly). Spectral renders that show
real colour come with the spectral render loop.
"""

from __future__ import annotations

from importlib import resources

import numpy as np
import pytest
from scipy import ndimage

from lenscompare.lenses import load_prescription
from lenscompare.metrics import channel_blur_disks, lateral_color
from lenscompare.render import render
from lenscompare.scene import load_scene


def shipped(name):
    return load_scene(resources.files("lenscompare.reference_scenes") / f"{name}.toml")


@pytest.fixture(scope="module")
def dot_grid():
    return render(shipped("dot_grid"), model="pinhole", spp=16, threads=2, progress=False).pixels


def magnified(channel, factor):
    """The channel magnified by ``factor`` about the image centre (cubic spline)."""
    height, width = channel.shape
    rows, cols = np.mgrid[0:height, 0:width].astype(float)
    cy, cx = height / 2.0 - 0.5, width / 2.0 - 0.5  # the centre in pixel-index coordinates
    return ndimage.map_coordinates(channel, [cy + (rows - cy) / factor, cx + (cols - cx) / factor], order=3)


def test_radial_shift_of_red_against_blue_is_measured_at_every_field(dot_grid):
    k = 0.004  # red imaged 0.4 % larger, blue 0.4 % smaller: R - B = 2 k r
    image = dot_grid.astype(float).copy()
    image[..., 0] = magnified(image[..., 0], 1.0 + k)
    image[..., 2] = magnified(image[..., 2], 1.0 - k)
    result = lateral_color(image)
    inside = result.field_radius_px < 180  # dots whole inside the frame in every channel
    assert inside.sum() >= 100
    expected = 2.0 * k * result.field_radius_px[inside]
    assert expected.max() > 1.0
    # Cubic resampling of a 16-spp render: a few hundredths of a pixel.
    np.testing.assert_allclose(result.radial_shift_px[inside], expected, atol=0.05)
    np.testing.assert_allclose(result.shift_px[inside], np.abs(expected), atol=0.06)


def test_a_white_render_through_a_lens_that_does_not_disperse_shows_no_colour():
    scene = shipped("dot_grid")
    scene = scene.with_camera(model="lens", lens=load_prescription("dgauss.50mm"), f_number=8.0)
    image = render(scene, spp=8, threads=2, progress=False).pixels
    result = lateral_color(image)
    assert len(result.shift_px) >= 100
    assert np.abs(result.radial_shift_px).max() < 1e-6 and result.shift_px.max() < 1e-6


@pytest.fixture(scope="module")
def blur_disks():
    return render(shipped("blur_disks"), model="thin", spp=16, threads=2, progress=False).pixels


def test_a_channel_blurred_by_a_disk_reads_the_diameters_added_in_quadrature(blur_disks):
    radius = 4
    yy, xx = np.mgrid[-radius:radius + 1, -radius:radius + 1]
    kernel = (xx ** 2 + yy ** 2 <= radius ** 2).astype(float)
    kernel /= kernel.sum()
    kernel_diameter = 4.0 * np.sqrt((kernel * xx ** 2).sum())  # its own second-moment diameter (per axis)
    image = blur_disks.astype(float).copy()
    image[..., 0] = ndimage.convolve(image[..., 0], kernel, mode="constant")
    plain = channel_blur_disks(blur_disks, min_separation_px=12.0)
    red = channel_blur_disks(image, min_separation_px=12.0)
    assert len(red.diameter_px) == len(plain.diameter_px) >= 5
    np.testing.assert_allclose(plain.red_minus_blue_px, 0.0, atol=1e-9)  # a white render: channels alike
    expected = np.hypot(plain.diameter_px[:, 0], kernel_diameter)
    np.testing.assert_allclose(red.diameter_px[:, 0], expected, rtol=0.02)
    np.testing.assert_allclose(red.diameter_px[:, 2], plain.diameter_px[:, 2], rtol=0.02)
    assert (red.red_minus_blue_px > 0.3).all()


def test_bad_input_is_refused_naming_it():
    with pytest.raises(ValueError, match="RGB"):
        lateral_color(np.zeros((10, 10)))
    with pytest.raises(ValueError, match="max_distance_px"):
        lateral_color(np.zeros((10, 10, 3)), max_distance_px=-1)
