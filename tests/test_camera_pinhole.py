"""Pinhole camera: geometric invariants of its rays and where points land.

Like Mitsuba's sensor tests, the C++ camera is checked from Python through
rays it generates for chosen samples, and through renders of point sources.
"""

import numpy as np
import pytest

from lenscompare import _native
from lenscompare.cameras import camera_for
from lenscompare.cameras import CameraFrame
from lenscompare.metrics.blur_disk import find_point_sources
from lenscompare.optics import focus_film_distance_mm
from lenscompare.render import render
from lenscompare.scene import parse_scene

from helpers import camera_scene_text, sphere_text


def rays(camera, raster_px, lens=None):
    raster_px = np.ascontiguousarray(raster_px, dtype=np.float32)
    n = len(raster_px)
    lens = np.full((n, 2), 0.5, np.float32) if lens is None else np.ascontiguousarray(lens, dtype=np.float32)
    origin, direction, weight = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n, np.float32)
    _native.generate_rays(camera, raster_px, lens, origin, direction, weight)
    return origin, direction, weight


def test_centre_ray_goes_down_the_view_axis_and_edges_span_the_field():
    scene = parse_scene(camera_scene_text(model="pinhole", position=(1.0, 2.0, 3.0), look_at=(2.0, 2.5, 5.0)))
    info = camera_for(scene, "pinhole")
    camera = info.native()
    origin, direction, weight = rays(camera, [[180, 120], [360, 120], [180, 0]])
    _, right, up, forward = (np.array(v) for v in CameraFrame.of(scene.camera))
    np.testing.assert_allclose(origin, [[1.0, 2.0, 3.0]] * 3)
    np.testing.assert_allclose(direction[0], forward, atol=1e-12)
    assert np.all(weight == 1.0)
    # Right edge of the film: half-angle atan(18 / d'); top edge: atan(12 / d').
    d_prime = focus_film_distance_mm(2000.0, 50.0)
    assert info.film_distance_mm == pytest.approx(d_prime)
    assert np.degrees(np.arctan2(direction[1] @ right, direction[1] @ forward)) == pytest.approx(
        np.degrees(np.arctan(18.0 / d_prime)), abs=1e-9)
    assert np.degrees(np.arctan2(direction[2] @ up, direction[2] @ forward)) == pytest.approx(
        np.degrees(np.arctan(12.0 / d_prime)), abs=1e-9)


def test_plus_x_is_right_and_plus_y_is_up():
    # Default camera at the origin looking at +z with up +y (DESIGN.md).
    objects = sphere_text((0.4, 0.0, 3.0), 0.02) + sphere_text((0.0, 0.3, 3.0), 0.02)
    image = render(parse_scene(camera_scene_text(model="pinhole", spp=16, objects=objects)), threads=2)
    sources = find_point_sources(image.pixels)
    assert len(sources) == 2
    by_x = sorted(sources, key=lambda s: s.centroid_px[0])
    right_one, up_one = by_x[1], by_x[0]
    assert right_one.centroid_px[0] > 180 + 10 and abs(right_one.centroid_px[1] - 120) < 1
    assert up_one.centroid_px[1] < 120 - 10 and abs(up_one.centroid_px[0] - 180) < 1


def analytic_raster_px(point, scene, film_distance_mm):
    """Projection of a world point, derived independently of the C++ code."""
    origin, right, up, forward = (np.array(v) for v in CameraFrame.of(scene.camera))
    p = np.asarray(point) - origin
    x, y, z = p @ right, p @ up, p @ forward
    film_w, film_h = scene.camera.film_mm
    x_film_mm, y_film_mm = film_distance_mm * x / z, film_distance_mm * y / z
    w, h = scene.camera.resolution
    return np.array([(x_film_mm / film_w + 0.5) * w, (0.5 - y_film_mm / film_h) * h])


def test_point_sources_land_on_the_analytic_projection_tilted_camera():
    """Rendered centroids of small emissive spheres within 0.05 px of the analytic projection.

    The camera is off the origin, tilted down and sideways, with a non-default
    up vector (a rolled camera).
    """
    text = camera_scene_text(model="pinhole", position=(0.3, 1.2, -0.5), look_at=(-0.4, 0.2, 4.0),
                             up=(0.25, 1.0, 0.1), resolution=(240, 160), spp=1024)
    scene = parse_scene(text)
    origin, right, up, forward = (np.array(v) for v in CameraFrame.of(scene.camera))
    # Points spread over the frame at different depths (camera-space x, y, z in m).
    camera_points = [(-0.8, 0.5, 3.0), (0.9, -0.4, 3.5), (0.0, 0.0, 2.5), (-0.3, -0.4, 2.2), (1.2, 0.7, 5.0)]
    world = [origin + right * x + up * y + forward * z for x, y, z in camera_points]
    radius_m = [0.004 * z for _, _, z in camera_points]  # image about 1 px wide
    scene = parse_scene(text + "".join(sphere_text(tuple(p), r) for p, r in zip(world, radius_m)))

    image = render(scene, threads=2)
    d_prime = focus_film_distance_mm(2000.0, 50.0)
    expected = np.array([analytic_raster_px(p, scene, d_prime) for p in world])
    measured = np.array([s.centroid_px for s in find_point_sources(image.pixels)])
    assert len(measured) == len(expected)
    # Pair each expectation with the nearest measurement.
    errors = [np.min(np.linalg.norm(measured - e, axis=1)) for e in expected]
    print("projection errors px:", np.round(errors, 4))
    assert max(errors) < 0.05, errors
