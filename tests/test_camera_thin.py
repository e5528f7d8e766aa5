"""Thin-lens camera: rays through the plane of focus, and blur disks of equation 5."""

import numpy as np
import pytest

from lenscompare.cameras import camera_for
from lenscompare.cameras import CameraFrame
from lenscompare.metrics.blur_disk import find_point_sources
from lenscompare.optics import circle_of_confusion_mm, focus_film_distance_mm
from lenscompare.render import render
from lenscompare.scene import parse_scene

from helpers import camera_scene_text, sphere_text
from test_camera_pinhole import rays

TILTED = dict(position=(0.3, 1.2, -0.5), look_at=(-0.4, 0.2, 4.0), up=(0.25, 1.0, 0.1))


@pytest.mark.parametrize("mapping", ["concentric", "polar"])
def test_every_ray_passes_through_the_focus_point_and_leaves_the_lens_disk(mapping):
    text = camera_scene_text(f_number=2.0, focus_distance=3.0, **TILTED)
    text = text.replace("spp = 64", f'spp = 64\ndisk_mapping = "{mapping}"')
    scene = parse_scene(text)
    camera = camera_for(scene, "thin").native(disk_mapping=scene.render.disk_mapping)
    origin_w, right, up, forward = (np.array(v) for v in CameraFrame.of(scene.camera))
    rng = np.random.default_rng(1)
    for raster in ([180.0, 120.0], [3.5, 230.25], [359.0, 0.5]):
        lens = rng.random((500, 2))
        origin, direction, weight = rays(camera, np.tile(raster, (500, 1)), lens)
        assert np.all(weight == 1.0)
        # Lens points lie in the lens plane, inside the aperture radius f / 2N.
        offset = origin - origin_w
        np.testing.assert_allclose(offset @ forward, 0.0, atol=1e-12)
        assert np.max(np.linalg.norm(offset, axis=1)) <= 50.0 / 2.0 / 2.0 / 1000.0 + 1e-12
        # All rays meet at one point on the plane of focus (depth 3 m along the axis).
        t = (3.0 - offset @ forward) / (direction @ forward)
        hits = origin + direction * t[:, None]
        assert np.max(np.linalg.norm(hits - hits.mean(axis=0), axis=1)) < 1e-9
    # The sample that maps to the lens centre, at the film centre, goes straight down the axis.
    centre_sample = [[0.5, 0.5]] if mapping == "concentric" else [[0.0, 0.3]]
    origin, direction, _ = rays(camera, [[180.0, 120.0]], centre_sample)
    np.testing.assert_allclose(origin[0], origin_w, atol=1e-15)
    np.testing.assert_allclose(direction[0], forward, atol=1e-12)


def test_blur_disks_match_equation_5_off_centre_tilted_camera():
    """Blur disks of small emissive spheres, in front of and behind focus, within 2 % of eq. 5.

    Measured as flux-weighted second moments, corrected for the pixel
    footprint and for each sphere's own (sharp) image on the film.
    """
    f_mm, n, focus_m = 50.0, 1.4, 2.0
    width, height = 480, 320
    pitch_mm = 36.0 / width
    text = camera_scene_text(f_number=n, focus_distance=focus_m, resolution=(width, height), spp=256, **TILTED)
    scene = parse_scene(text)
    origin, right, up, forward = (np.array(v) for v in CameraFrame.of(scene.camera))
    d_prime = focus_film_distance_mm(focus_m * 1000.0, f_mm)
    # Camera-space points (x, y, axial depth z): two in front of focus, two behind, off-centre.
    points = [(-0.2, 0.1, 1.0), (0.25, -0.15, 1.3), (-0.8, -0.5, 4.0), (2.0, 1.2, 8.0)]
    radius_m = [0.0015 * z for *_, z in points]
    world = [origin + right * x + up * y + forward * z for x, y, z in points]
    scene = parse_scene(text + "".join(sphere_text(tuple(p), r) for p, r in zip(world, radius_m)))

    image = render(scene, threads=2)
    expected_px = [circle_of_confusion_mm(z * 1000.0, focus_distance_mm=focus_m * 1000.0, focal_length_mm=f_mm,
                                          aperture_diameter_mm=f_mm / n) / pitch_mm for *_, z in points]
    # Where each point projects (its chief ray), to pair measurements with points.
    projected = [np.array([(d_prime * x / z / 36.0 + 0.5) * width, (0.5 - d_prime * y / z / 24.0) * height])
                 for x, y, z in points]
    sources = find_point_sources(image.pixels)
    assert len(sources) == len(points)
    for (x, y, z), r, proj, expected in zip(points, radius_m, projected, expected_px):
        source = min(sources, key=lambda s: np.linalg.norm(np.array(s.centroid_px) - proj))
        sphere_image_px = 2.0 * r * 1000.0 * d_prime / (z * 1000.0) / pitch_mm
        from lenscompare.metrics.blur_disk import measure_blur_disk

        disk = measure_blur_disk(image.pixels, center_px=source.centroid_px,
                                 window_radius_px=expected + sphere_image_px + 4,
                                 source_diameter_px=sphere_image_px)
        error = disk.second_moment_diameter_px / expected - 1.0
        print(f"depth {z} m: eq.5 {expected:.3f} px, measured {disk.second_moment_diameter_px:.3f} px, "
              f"error {100 * error:+.2f} %")
        assert abs(error) < 0.02
