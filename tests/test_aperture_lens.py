"""The lens system's N-blade stop: the entrance pupil becomes the polygon,
the SIMD trace kernels still give the scalar trace's rays (bits in double), and the working
f-number for diffraction comes from the exit pupil."""

import math

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from lenscompare._native import diagnostics
from lenscompare.cameras import CameraFrame, camera_for
from lenscompare.optics import aperture_vertices, inside_aperture

from lens_batch_check import assert_batch_matches_scalar
from test_camera_lens import KERNELS, lens_scene, rays


def bladed(scene, blades, rotation_deg=0.0):
    return scene.with_camera(aperture_blades=blades, aperture_rotation_deg=rotation_deg)


@pytest.mark.parametrize("lens,f_number", [("dgauss.50mm", None), ("dgauss.50mm", 4.0), ("wide.22mm", 8.0),
                                           ("telephoto.250mm", None)])
@pytest.mark.parametrize("blades", [5, 6])
@pytest.mark.parametrize("precision", ["double", "single"])
def test_lockstep_batch_trace_gives_the_scalar_trace_with_blades(lens, f_number, blades, precision):
    scene = lens_scene(lens, f_number=f_number, focus_distance=10.0 if lens.startswith("telephoto") else 2.0)
    camera = camera_for(bladed(scene, blades, 12.0), "lens").native()
    rng = np.random.default_rng(5)
    n = 20000
    raster = (rng.random((n, 2)) * [360, 240]).astype(np.float32)
    u = rng.random((n, 2)).astype(np.float32)
    scalar = rays(camera, raster, u)
    assert np.isfinite(scalar[2]).all() and (scalar[2] > 0).any()
    # The blades stop some rays the round stop passes.
    round_stop = rays(camera_for(scene, "lens").native(), raster, u)
    assert (scalar[2] > 0).sum() < (round_stop[2] > 0).sum()

    def batched():
        out = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n, np.float32)
        diagnostics.generate_lens_rays_batched(camera, raster, u, *out)
        return out

    assert_batch_matches_scalar(camera, batched, scalar, kernels=KERNELS, precision=precision)


@pytest.mark.parametrize("blades,rotation_deg", [(5, 0.0), (6, 15.0), (9, -7.0)])
def test_entrance_pupil_is_the_polygon_of_the_circles_area_turned_as_asked(blades, rotation_deg):
    """Rays from the film centre cross the entrance-pupil plane (through
    camera.position, square to the view) inside the N-gon of the entrance
    pupil's area, upright, and fill it."""
    scene = bladed(lens_scene("dgauss.50mm", f_number=4.0, focus_distance=1e6), blades, rotation_deg)
    value = camera_for(scene, "lens")
    camera = value.native()
    n = 40000
    u = np.random.default_rng(2).random((n, 2)).astype(np.float32)
    origin, direction, weight = rays(camera, np.tile([180.0, 120.0], (n, 1)).astype(np.float32), u)
    alive = weight > 0
    frame_origin, right, up, forward = (np.array(v) for v in CameraFrame.of(scene.camera))
    t = -((origin[alive] - frame_origin) @ forward) / (direction[alive] @ forward)
    hits = origin[alive] + direction[alive] * t[:, None] - frame_origin
    x_mm, y_mm = 1000.0 * hits @ right, 1000.0 * hits @ up
    radius_mm = value.paraxial.entrance_pupil_diameter_mm / 2.0
    # Inside the predicted polygon (1 % for the pupil's own aberrations) ...
    assert inside_aperture(x_mm / 1.01, y_mm / 1.01, blades=blades, rotation_deg=rotation_deg,
                           radius=radius_mm).mean() == 1.0
    # ... and filling it: its hull has the circle's area, its corners point where asked.
    hull = ConvexHull(np.stack([x_mm, y_mm], axis=1))
    assert hull.volume == pytest.approx(math.pi * radius_mm ** 2, rel=0.02)
    corners = aperture_vertices(blades, rotation_deg, radius=radius_mm)
    points = np.stack([x_mm, y_mm], axis=1)
    for corner in corners:
        nearest = points[np.argmin(np.linalg.norm(points - corner, axis=1))]
        angle = math.degrees(math.atan2(nearest[1], nearest[0]) - math.atan2(corner[1], corner[0]))
        assert abs((angle + 180) % 360 - 180) < 2.0


def test_working_f_number_comes_from_the_exit_pupil():
    scene = lens_scene("dgauss.50mm", f_number=8.0, focus_distance=1e6)
    value = camera_for(scene, "lens")
    data = value.paraxial
    # At infinity the image-space working f-number of a lens is its f-number
    # only for a unit pupil magnification; the exit pupil says what it is.
    expected = (value.film_z_mm - data.exit_pupil_position_mm) / data.exit_pupil_diameter_mm
    assert value.working_f_number == pytest.approx(expected)
    assert value.working_f_number == pytest.approx(8.0, rel=0.1)
    near = camera_for(lens_scene("dgauss.50mm", f_number=8.0, focus_distance=0.5), "lens")
    assert near.working_f_number > value.working_f_number * 1.05  # focusing close slows the lens
