"""The native lens trace against the Python one (lenscompare.lenses.trace), ray
for ray: two implementations of the same Snell trace must send the same rays
to the same places and block the same ones.

The native module exposes no raw trace, so the test goes through the camera:
a lens-system camera with the brute-force pupil (``diagnostics.with_brute_force_pupil``: a
regular 64-gon holding a disk of 1.5 rear semi-apertures, the same for every
film point) turns (raster point, lens sample) into a film point and a point on
the rear-vertex plane by a rule simple enough to write out here
(native/src/lens/exit_pupil.cpp ``bounding_disk``, ``ExitPupil::pick``,
lens_aim.h ``aim_one``). The same film point is traced toward the same pupil
point with ``trace_from_film``, and the native world ray is taken back to the
lens frame. The camera's frame is the identity and its entrance pupil sits at
z = 0, so that conversion costs only a few roundings.
"""

import math

import numpy as np
import pytest

from lenscompare import _native
from lenscompare.cameras.lens import lens_elements
from lenscompare.lenses import film_distance_mm, load_prescription, stopped_down, trace_from_film

from helpers import REPO


TEST_LENSES = REPO / "tests" / "data" / "lenses"
LENSES = ["dgauss.50mm", "wide.22mm", "fisheye.10mm", "telephoto.250mm",
          *(str(TEST_LENSES / f"{name}.dat") for name in (
              "thin_singlet", "biconvex_stop_front", "cemented_zero_layer", "planoconvex_flat_front",
              "planoconvex_nearly_flat_front", "tir_prism"))]
PUPIL_ANGLES = 64  # kPupilAngles
WIDTH_PX, HEIGHT_PX, FILM_MM = 360, 240, (36.0, 24.0)


def _camera(prescription, film_z_mm):
    camera = _native.LensSystemCamera((0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0),
                                      WIDTH_PX, HEIGHT_PX, *FILM_MM, **lens_elements(prescription),
                                      film_z_mm=film_z_mm, entrance_pupil_z_mm=0.0)
    return _native.diagnostics.with_brute_force_pupil(camera)


def _film_rays(prescription, film_z_mm, raster, u):
    """The rays the brute-force camera aims from the film (lens frame, mm):
    origins, unit directions, and each sample's pupil-polygon area."""
    raster, u = raster.astype(np.float64), u.astype(np.float64)
    # Film point: the image is inverted on the film.
    x = (0.5 * WIDTH_PX - raster[:, 0]) * (FILM_MM[0] / WIDTH_PX)
    y = (raster[:, 1] - 0.5 * HEIGHT_PX) * (FILM_MM[1] / HEIGHT_PX)
    r = np.sqrt(x * x + y * y)
    # The 64-gon around a disk of 1.5 rear semi-apertures, centred on the axis,
    # built for a film point on +x; u.y picks a fan triangle and a place across it.
    radius = 1.5 * prescription.surfaces[-1].semi_aperture_mm / math.cos(math.pi / PUPIL_ANGLES)
    k = np.minimum(np.floor(u[:, 1] * PUPIL_ANGLES), PUPIL_ANGLES - 1)
    across = np.clip((u[:, 1] - k / PUPIL_ANGLES) * PUPIL_ANGLES, 0.0, 1.0)
    a = 2.0 * math.pi * k / PUPIL_ANGLES
    b = 2.0 * math.pi * ((k + 1) % PUPIL_ANGLES) / PUPIL_ANGLES
    s = np.sqrt(u[:, 0])
    lx = s * ((1.0 - across) * radius * np.cos(a) + across * radius * np.cos(b))
    ly = s * ((1.0 - across) * radius * np.sin(a) + across * radius * np.sin(b))
    # ... rotated to the film point's azimuth.
    cos_phi = np.where(r > 0, x / np.where(r > 0, r, 1.0), 1.0)
    sin_phi = np.where(r > 0, y / np.where(r > 0, r, 1.0), 0.0)
    px, py = cos_phi * lx - sin_phi * ly, sin_phi * lx + cos_phi * ly
    plane_z_mm = prescription.vertex_z_mm[-1]
    origins = np.stack([x, y, np.full_like(x, film_z_mm)], axis=1)
    directions = np.stack([px - x, py - y, np.full_like(x, plane_z_mm - film_z_mm)], axis=1)
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    area_mm2 = PUPIL_ANGLES * math.sin(2.0 * math.pi / PUPIL_ANGLES) * 0.5 * radius * radius
    return origins, directions, area_mm2


def _samples(n, seed):
    rng = np.random.default_rng(seed)
    raster = rng.random((n, 2)) * [WIDTH_PX, HEIGHT_PX]
    raster[:8] = [[0, 0], [WIDTH_PX, HEIGHT_PX], [0, HEIGHT_PX], [WIDTH_PX, 0], [180, 120], [180, 0], [0, 120],
                  [359.5, 119.5]]
    u = rng.random((n, 2))
    u[8:16] = [[0.9999999, 0.5], [0.0, 0.0], [0.5, 0.9999999], [1e-7, 1e-7], [1.0, 0.25], [0.25, 1.0], [0.5, 0.0],
               [0.999, 0.999]]
    return raster.astype(np.float32), u.astype(np.float32)


# Every lens wide open, and the ones with an aperture stop also stopped down
# (f/64: a tiny stop that blocks almost everything, so it gets more rays).
CASES = [(lens, None) for lens in LENSES] + [
    ("dgauss.50mm", 8.0), ("dgauss.50mm", 64.0), ("wide.22mm", 8.0), ("telephoto.250mm", 11.0),
    (str(TEST_LENSES / "thin_singlet.dat"), 16.0), (str(TEST_LENSES / "biconvex_stop_front.dat"), 8.0)]


@pytest.mark.parametrize("lens, f_number", CASES,
                         ids=[f"{lens.rsplit('/', 1)[-1]}-f{n or 'open'}" for lens, n in CASES])
def test_native_and_python_traces_agree_ray_for_ray(lens, f_number):
    prescription = load_prescription(lens)
    if f_number is not None:
        prescription = stopped_down(prescription, f_number)
    film_z_mm = prescription.total_track_mm + film_distance_mm(prescription, 3.0 if "telephoto" not in lens else 10.0)
    camera = _camera(prescription, film_z_mm)
    raster, u = _samples(200000 if f_number == 64.0 else 20000, seed=17)
    n = len(raster)
    origin_w, direction_w, weight = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n, np.float32)
    _native.generate_rays(camera, raster, u, origin_w, direction_w, weight)
    # A blocked sample comes back as zeros (a ray that passed has a unit
    # direction); not as weight 0, which the brute-force camera at f/64 gives
    # every ray (its centre calibration grid misses the tiny pupil).
    native_passed = np.any(direction_w != 0.0, axis=1)
    # World (m; identity frame, entrance pupil at lens z = 0, +z toward the scene) -> lens frame (mm, +z to the film)
    native_origin = origin_w * [1e3, 1e3, -1e3]
    native_direction = direction_w * [1.0, 1.0, -1.0]

    origins, directions, area_mm2 = _film_rays(prescription, film_z_mm, raster, u)
    python = trace_from_film(prescription, origins, directions)

    blocked_differently = np.flatnonzero(native_passed != python.passed)
    assert blocked_differently.size == 0, (
        f"{blocked_differently.size} rays blocked by one trace only, e.g. raster {raster[blocked_differently[:3]]}, "
        f"u {u[blocked_differently[:3]]}, native passed {native_passed[blocked_differently[:3]]}")
    passed = python.passed
    assert 20 <= passed.sum() < n, passed.sum()  # both kinds are compared
    position_error = np.abs(native_origin[passed] - python.origins_mm[passed]).max()
    direction_error = np.abs(native_direction[passed] - python.directions[passed]).max()
    print(f"{passed.sum()} of {n} passed; largest differences {position_error:.2g} mm, {direction_error:.2g}")
    assert position_error < 1e-9, position_error
    assert direction_error < 1e-9, direction_error
    # The weight (film irradiance): cos^4 of the aimed ray times the pupil area
    # over the squared axial distance, normalised at the centre.
    cos_theta = -directions[passed, 2]
    expected = (cos_theta ** 4 * area_mm2 / (film_z_mm - prescription.vertex_z_mm[-1]) ** 2
                * camera.inverse_centre_irradiance)
    np.testing.assert_allclose(weight[passed], expected, rtol=1e-6)
