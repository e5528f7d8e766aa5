"""Tests for lenscompare.lenses.trace (exact ray trace) and .analysis.

Reference numbers come from the shared lens README (optiland, real rays):
Double Gauss distortion -0.221 % at 10 deg and -1.07 % at 20 deg; relative
illumination about 0.70 and 0.29; fisheye image circle near 13.4 mm; real-ray
f-numbers 2.018, 3.995, 5.592, 2.788.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lenscompare.errors import InputError
from lenscompare.lenses import (
    aperture_stop_index,
    chief_ray_distortion_percent,
    chief_ray_film_height_mm,
    film_distance_mm,
    image_circle_radius_mm,
    load_prescription,
    paraxial_data,
    real_f_number,
    relative_illumination,
    trace_from_film,
    trace_from_scene,
)
from lenscompare.lenses import analysis
from lenscompare.lenses.paraxial import stopped_down
from lenscompare.lenses.trace import TOWARD_FILM, _cross_surface

DATA = Path(__file__).parent / "data" / "lenses"
CLASSICS = ("dgauss.50mm", "fisheye.10mm", "telephoto.250mm", "wide.22mm")


def _lens(name: str):
    return load_prescription(DATA / f"{name}.dat" if "_" in name else name)


def _axis_crossing_z(rays):
    """z where each (meridional, y != 0) ray crosses the axis."""
    o, d = rays.origins_mm, rays.directions
    return o[..., 2] - o[..., 1] * d[..., 2] / d[..., 1]


# --- the trace --------------------------------------------------------------


@pytest.mark.parametrize("name", ["biconvex_stop_front", "planoconvex_flat_back", *CLASSICS])
def test_near_axis_rays_focus_at_the_paraxial_rear_focal_point(name):
    lens = _lens(name)
    data = paraxial_data(lens)
    heights = np.array([1e-5, 1e-4]) * data.entrance_pupil_diameter_mm
    origins = np.stack([np.zeros(2), heights, np.full(2, -50.0)], axis=1)
    rays = trace_from_scene(lens, origins, [0.0, 0.0, 1.0])
    assert rays.passed.all()
    assert _axis_crossing_z(rays) == pytest.approx(data.rear_focal_point_mm, abs=1e-6)


def test_spherical_aberration_pulls_marginal_rays_of_a_singlet_inward():
    lens = _lens("planoconvex_flat_back")
    origins = [[0.0, h, -10.0] for h in (1.0, 5.0, 9.0)]
    z = _axis_crossing_z(trace_from_scene(lens, origins, [0.0, 0.0, 1.0]))
    assert z[0] > z[1] > z[2]  # undercorrected, as every positive singlet


@pytest.mark.parametrize("name", CLASSICS)
def test_from_the_rear_focal_point_rays_leave_parallel_at_height_f_times_slope(name):
    lens = _lens(name)
    data = paraxial_data(lens)
    slope = 1e-6
    rays = trace_from_film(lens, [0.0, 0.0, data.rear_focal_point_mm], [0.0, slope, -1.0])
    assert rays.passed
    assert rays.directions[1] == pytest.approx(0.0, abs=1e-6 * slope)
    height = rays.origins_mm[1] - rays.directions[1] / rays.directions[2] * rays.origins_mm[2]
    assert height == pytest.approx(data.effective_focal_length_mm * slope, rel=1e-5)


@pytest.mark.parametrize("name", CLASSICS)
def test_tracing_back_returns_to_the_film_point(name):
    lens = _lens(name)
    film_z = lens.total_track_mm + film_distance_mm(lens, math.inf)
    rng = np.random.default_rng(1)
    rear = lens.surfaces[-1].semi_aperture_mm
    # 2000 rays: through the wide-angle lens only some 7 % pass (15 of 200 for some seeds)
    targets = np.concatenate([rng.uniform(-rear, rear, (2000, 2)) * 0.7,
                              np.full((2000, 1), lens.total_track_mm)], axis=1)
    origins = np.concatenate([rng.uniform(-3, 3, (2000, 2)), np.full((2000, 1), film_z)], axis=1)
    out = trace_from_film(lens, origins, targets - origins)
    assert out.passed.sum() > 100
    back = trace_from_scene(lens, out.origins_mm[out.passed] + 5.0 * out.directions[out.passed],
                            -out.directions[out.passed])
    assert back.passed.all()
    landed = back.origins_mm + back.directions * (
        (film_z - back.origins_mm[:, 2]) / back.directions[:, 2])[:, None]
    np.testing.assert_allclose(landed, origins[out.passed], atol=1e-9)


def test_refraction_at_a_plane_obeys_snell():
    lens = _lens("planoconvex_flat_front")  # plane into n = 1.5
    angle = math.radians(30.0)
    rays = trace_from_scene(lens, [0.0, 2.0, -1.0], [0.0, math.sin(angle), math.cos(angle)],
                            last=0)
    assert rays.passed
    assert rays.directions[1] == pytest.approx(math.sin(angle) / 1.5, rel=1e-14)
    assert np.linalg.norm(rays.directions) == pytest.approx(1.0, rel=1e-15)


def test_total_internal_reflection_blocks_the_ray_without_nan():
    lens = _lens("tir_prism")  # R = 10 front into n = 1.9, flat back
    rays = trace_from_scene(lens, [[0, 9.0, -1.0], [0, 1.0, -1.0]], [0.0, 0.0, 1.0])
    assert rays.passed.tolist() == [False, True]
    assert np.isfinite(rays.origins_mm).all() and np.isfinite(rays.directions).all()
    assert (rays.origins_mm[0] == 0).all() and (rays.directions[0] == 0).all()
    # It is the internal reflection that blocks it, not an aperture:
    assert not trace_from_scene(lens, [0, 9.0, -1.0], [0.0, 0.0, 1.0], clip=False).passed
    inside = trace_from_scene(lens, [0, 9.0, -1.0], [0.0, 0.0, 1.0], last=0)
    assert inside.passed and abs(inside.origins_mm[1]) < 9.5
    incidence = math.asin(math.hypot(*inside.directions[:2]))  # on the flat back
    assert incidence > math.asin(1 / 1.9)


def test_rays_outside_an_aperture_are_blocked():
    lens = _lens("planoconvex_flat_back")  # semi-aperture 10
    rays = trace_from_scene(lens, [[0, 9.99, -1], [0, 10.01, -1], [7.1, 7.1, -1]], [0, 0, 1])
    assert rays.passed.tolist() == [True, False, False]
    stop_first = _lens("biconvex_stop_front")  # stop semi-aperture 5, lens 10
    rays = trace_from_scene(stop_first, [[0, 4.99, -1], [0, 5.01, -1]], [0, 0, 1])
    assert rays.passed.tolist() == [True, False]
    assert trace_from_scene(stop_first, [0, 5.01, -1], [0, 0, 1], clip=False).passed


def test_a_ray_that_misses_a_sphere_is_blocked():
    lens = _lens("tir_prism")  # front radius 10
    rays = trace_from_scene(lens, [0, 10.5, -1.0], [0.0, 0.0, 1.0], clip=False)
    assert not rays.passed and (rays.directions == 0).all()


def test_a_ray_turned_back_by_refraction_is_blocked():
    # Glass (1.5) to air at the rim of a steep surface (R = 10, rim at 9.9 mm):
    # the ray crosses the right way and is not totally reflected, but leaves
    # heading back toward -z (cf. pbrt-v3 issue #92).
    c, rim = 0.1, 9.9
    sag = 10.0 - math.sqrt(100.0 - rim * rim)
    hit = np.array([rim, 0.0, sag])
    d = np.array([-1.0, 0.0, 0.01]) / math.hypot(1.0, 0.01)
    # The same refraction by hand: Snell's law in vector form.
    normal = np.array([0.0, 0.0, 1.0]) - c * hit
    cos_in = d @ normal
    assert cos_in > 0 and 1.5 * math.sqrt(1 - cos_in**2) < 1  # right way, no TIR
    cos_out = math.sqrt(1 - 1.5**2 * (1 - cos_in**2))
    assert (1.5 * d + (cos_out - 1.5 * cos_in) * normal)[2] < 0  # turned back
    o = (hit - d)[None, :]
    args = (o, d[None, :], np.array([True]), c, 10.0, 0.0)
    _, _, alive = _cross_surface(*args, 1.5, 1.0, TOWARD_FILM)
    assert not alive[0]
    _, _, alive = _cross_surface(*args, 1.0, 1.0, TOWARD_FILM)  # no refraction: fine
    assert alive[0]


def test_unusable_input_rays_are_blocked():
    lens = _lens("dgauss.50mm")
    origins = [[0, 0, 80.0], [0, 0, 80.0], [np.nan, 0, 80.0], [0, 0, np.inf], [0, 0, 80.0]]
    directions = [[0, 0, 1.0], [0, 0, 0.0], [0, 0, -1.0], [0, 0, -1.0], [0, 0, -1.0]]
    rays = trace_from_film(lens, origins, directions)
    assert rays.passed.tolist() == [False, False, False, False, True]
    assert np.isfinite(rays.origins_mm).all() and np.isfinite(rays.directions).all()


def test_shapes_broadcast_and_come_back():
    lens = _lens("dgauss.50mm")
    single = trace_from_film(lens, [0.0, 0.0, 70.0], [0.0, 0.0, -1.0])
    assert single.origins_mm.shape == (3,) and single.passed.shape == ()
    grid = trace_from_film(lens, np.zeros((2, 4, 3)) + [0, 0, 70.0], [0.0, 0.0, -1.0])
    assert grid.origins_mm.shape == (2, 4, 3) and grid.passed.shape == (2, 4)


def test_zero_thickness_layer_and_nearly_flat_surface_trace_like_their_twins():
    origins = np.array([[0.0, h, -10.0] for h in np.linspace(0.5, 9.5, 10)])
    direction = [0.0, -0.05, 1.0]
    for name, twin, tolerance in [("cemented_zero_layer", "singlet_no_layer", 1e-12),
                                  ("planoconvex_nearly_flat_front", "planoconvex_flat_front",
                                   1e-6)]:
        a = trace_from_scene(_lens(name), origins, direction)
        b = trace_from_scene(_lens(twin), origins, direction)
        assert a.passed.all() and b.passed.all()
        np.testing.assert_allclose(a.directions, b.directions, atol=tolerance)
        np.testing.assert_allclose(a.origins_mm, b.origins_mm, atol=tolerance * 10)


LENSES = [*CLASSICS, "tir_prism", "biconvex_stop_front", "cemented_zero_layer",
          "planoconvex_nearly_flat_front"]
_PRESCRIPTIONS = {name: _lens(name) for name in LENSES}
coordinate = st.floats(-60.0, 60.0, allow_nan=False)
component = st.floats(-1.0, 1.0, allow_nan=False)


@settings(max_examples=150, deadline=None)
@given(name=st.sampled_from(LENSES),
       rays=st.lists(st.tuples(coordinate, coordinate, component, component, component),
                     min_size=1, max_size=20),
       behind_mm=st.floats(0.0, 200.0))
def test_any_ray_comes_out_finite_or_blocked(name, rays, behind_mm):
    lens = _PRESCRIPTIONS[name]
    values = np.array(rays)
    origins = np.column_stack([values[:, 0], values[:, 1],
                               np.full(len(values), lens.total_track_mm + behind_mm)])
    with np.errstate(all="raise"):  # no floating-point warning leaks out either
        out = trace_from_film(lens, origins, values[:, 2:])
        back = trace_from_scene(lens, origins * [1, 1, -1] - [0, 0, 1], values[:, 2:] * [1, 1, -1])
    for result, travel in ((out, -1), (back, 1)):
        assert np.isfinite(result.origins_mm).all() and np.isfinite(result.directions).all()
        ok = result.passed
        np.testing.assert_allclose(np.linalg.norm(result.directions[ok], axis=1), 1.0, rtol=1e-12)
        assert (travel * result.directions[ok, 2] > 0).all()
        assert (result.directions[~ok] == 0).all() and (result.origins_mm[~ok] == 0).all()
    # Rays that leave toward the scene do so through the first clear aperture.
    first = lens.surfaces[0].semi_aperture_mm
    assert (np.hypot(*out.origins_mm[out.passed, :2].T) <= first * (1 + 1e-12)).all()


# --- analysis ---------------------------------------------------------------


def test_double_gauss_distortion_matches_the_reference():
    lens = _lens("dgauss.50mm")
    assert chief_ray_distortion_percent(lens, 10.0) == pytest.approx(-0.221, abs=0.005)
    assert chief_ray_distortion_percent(lens, 20.0) == pytest.approx(-1.07, abs=0.01)


def test_distortion_vanishes_on_the_axis_and_the_ideal_height_is_f_tan():
    lens = _lens("dgauss.50mm")
    assert chief_ray_distortion_percent(lens, 0.0) == 0.0
    assert abs(chief_ray_distortion_percent(lens, 0.05)) < 1e-5
    f = paraxial_data(lens).effective_focal_length_mm
    height = chief_ray_film_height_mm(lens, 20.0)
    percent = chief_ray_distortion_percent(lens, 20.0)
    assert height == pytest.approx(-f * math.tan(math.radians(20.0)) * (1 + percent / 100))


def test_the_chief_ray_goes_through_the_stop_centre():
    lens = _lens("wide.22mm")
    origin, direction = analysis._chief_ray(lens, math.radians(25.0), math.inf)
    at_stop = trace_from_scene(lens, origin, direction, last=aperture_stop_index(lens))
    assert at_stop.origins_mm[:2] == pytest.approx([0.0, 0.0], abs=1e-9)


def test_distortion_at_a_finite_focus_distance_is_finite_and_far_equals_infinity():
    lens = _lens("dgauss.50mm")
    near = chief_ray_distortion_percent(lens, 20.0, focus_distance_m=1.0)
    far = chief_ray_distortion_percent(lens, 20.0, focus_distance_m=1e12)
    assert math.isfinite(near) and near != pytest.approx(-1.07, abs=0.05)
    assert far == pytest.approx(chief_ray_distortion_percent(lens, 20.0), abs=1e-6)


def test_double_gauss_relative_illumination_matches_the_reference():
    lens = _lens("dgauss.50mm")
    assert relative_illumination(lens, 0.0) == 1.0
    assert relative_illumination(lens, 10.0, samples_across=200) == pytest.approx(0.70, abs=0.03)
    assert relative_illumination(lens, 20.0, samples_across=200) == pytest.approx(0.29, abs=0.03)


@pytest.mark.parametrize("name", ["dgauss.50mm", "wide.22mm", "telephoto.250mm"])
def test_relative_illumination_settles_as_the_stop_closes_to_a_pinpoint(name):
    """Once the stop alone limits every beam, closing it further changes nothing but the pupil's
    size. Counted on a grid over the whole first surface the beam had a few cells across at f/64
    and none at f/1000 (the Double Gauss read 1.54 at 10 deg, f/256); the grid now follows the beam."""
    lens = _lens(name)
    settled = relative_illumination(lens, 10.0, f_number=64.0, samples_across=200)
    assert 0.5 < settled < 1.0
    for f_number in (256.0, 2000.0):
        assert relative_illumination(lens, 10.0, f_number=f_number, samples_across=200) == pytest.approx(settled,
                                                                                                        abs=0.005)


def test_a_defocused_spot_shrinks_as_the_aperture_down_to_a_pinpoint_stop():
    """Equation 5: the blur of a point off the plane of focus is proportional to the aperture.
    On a grid over the whole first surface a beam at f/1000 fell between the rays (NaN)."""
    lens = _lens("dgauss.50mm")
    spots = {}
    for f_number in (64.0, 256.0, 1000.0):
        stopped = stopped_down(lens, f_number)
        film_z = stopped.total_track_mm + film_distance_mm(stopped, 3.0)
        spots[f_number] = analysis.traced_spot_diameter_mm(stopped, height_mm=0.0, distance_mm=1500.0,
                                                           film_z_mm=film_z)
    assert spots[256.0] == pytest.approx(spots[64.0] / 4, rel=0.02)
    assert spots[1000.0] == pytest.approx(spots[64.0] / 15.625, rel=0.02)


def test_stopping_down_reduces_vignetting():
    # At f/8 the stop limits every beam and only the cos^4 law (and distortion) is left.
    lens = _lens("dgauss.50mm")
    theta = math.radians(20.0)
    stopped = relative_illumination(lens, 20.0, f_number=8.0, samples_across=150)
    assert stopped == pytest.approx(math.cos(theta) ** 4, rel=0.1)
    assert stopped > relative_illumination(lens, 20.0, samples_across=150)


def test_fisheye_image_circle_is_near_13_4_mm_and_misses_the_film_corners():
    radius = image_circle_radius_mm(_lens("fisheye.10mm"))
    assert radius == pytest.approx(13.4, abs=0.1)
    assert radius < math.hypot(18.0, 12.0)


def test_an_unbounded_image_circle_is_found_in_few_traces(tmp_path, monkeypatch):
    """A flat rear surface lets grazing rays through from any film radius (found by planning
    random lenses, session 55): the outward scan doubles its step after 64, so it reaches its
    1e6 mm limit in about 80 traces, where even steps took 156,000 (six minutes)."""
    lens = tmp_path / "flat_rear.dat"
    lens.write_text("1000000000.0 5.0720 1.6071 29.7586\n-31.788390132750294 2.4014 1 29.7586\n"
                    "0 4.3375 0 24.2753\n-291.03220545099407 1.3335 1.7900 29.7586\ninf 3.8982 1 29.7586\n")
    calls = []
    lit = analysis._any_ray_passes_from_film

    def counted(*args):
        calls.append(args)
        if len(calls) > 1000:
            raise AssertionError("more than 1000 traces to bound the image circle")
        return lit(*args)

    monkeypatch.setattr(analysis, "_any_ray_passes_from_film", counted)
    assert math.isinf(image_circle_radius_mm(load_prescription(str(lens)), focus_distance_m=1e6))
    assert len(calls) < 100, len(calls)


def test_fisheye_chief_ray_reaches_the_image_circle_at_its_half_field():
    # Muller fisheye: 155.9 deg field, so the edge chief ray is at about 78 deg.
    lens = _lens("fisheye.10mm")
    assert abs(chief_ray_film_height_mm(lens, 77.0)) == pytest.approx(13.4, abs=0.15)
    assert chief_ray_distortion_percent(lens, 60.0) < -30.0  # far from f tan(theta)


@pytest.mark.parametrize("name, expected", [
    ("dgauss.50mm", 2.018), ("fisheye.10mm", 3.995),
    ("telephoto.250mm", 5.592), ("wide.22mm", 2.788),
])
def test_real_f_numbers_match_the_reference(name, expected):
    assert real_f_number(_lens(name)) == pytest.approx(expected, abs=0.0006)


def test_field_angles_outside_0_to_90_degrees_are_refused():
    lens = _lens("dgauss.50mm")
    for bad in (-1.0, 90.0, math.nan):
        with pytest.raises(InputError, match="field angle"):
            chief_ray_distortion_percent(lens, bad)


# --- rays side by side --------------------------------------------------------


def test_a_batch_traces_each_ray_bit_for_bit_as_it_would_alone():
    # The trace drops blocked rays between surfaces; a survivor's arithmetic is its own.
    lens = _lens("dgauss.50mm")
    rng = np.random.default_rng(7)
    origins = np.column_stack([rng.uniform(-20, 20, 300), rng.uniform(-20, 20, 300), np.full(300, -5.0)])
    directions = np.column_stack([rng.uniform(-0.3, 0.3, 300), rng.uniform(-0.3, 0.3, 300), np.ones(300)])
    batch = trace_from_scene(lens, origins, directions)
    assert 0 < batch.passed.sum() < 300  # some pass, some are blocked
    for i in range(300):
        alone = trace_from_scene(lens, origins[i], directions[i])
        assert bool(alone.passed) == batch.passed[i]
        assert np.array_equal(alone.origins_mm, batch.origins_mm[i])
        assert np.array_equal(alone.directions, batch.directions[i])
    assert not batch.origins_mm[~batch.passed].any() and not batch.directions[~batch.passed].any()


@pytest.mark.parametrize("name, focus_distance_m", [("fisheye.10mm", math.inf), ("dgauss.50mm", 3.0),
                                                    ("wide.22mm", math.inf)])
def test_chief_rays_found_together_are_the_ones_found_alone(name, focus_distance_m):
    lens = _lens(name)
    thetas = [math.radians(a) for a in np.linspace(0.5, 89.0, 25)]
    origins, directions, found = analysis._chief_rays(lens, thetas, focus_distance_m)
    assert found[0] and (found.all() if name == "fisheye.10mm" else not found[-1])  # past 45 deg the others have none
    for k, theta in enumerate(thetas):
        if found[k]:
            origin, direction = analysis._chief_ray(lens, theta, focus_distance_m)
            assert np.array_equal(origin, origins[k]) and np.array_equal(direction, directions[k])
        else:
            with pytest.raises(InputError, match="no chief ray"):
                analysis._chief_ray(lens, theta, focus_distance_m)


def test_bracketed_roots_converge_row_by_row_and_stop_where_a_function_fails():
    targets = np.array([2.0, 3.0, 5.0, 7.0])

    def cube_minus_target(x, rows):  # row 3 is not finite inside (1, 2): no root can be found there
        return np.where(rows == 3, np.nan, x ** 3 - targets[rows])

    a, b = np.array([1.0, 1.0, 1.0, 1.0]), np.array([2.0, 2.0, 2.0, 2.0])
    active = np.array([True, True, True, True])
    roots = analysis._bracketed_roots(cube_minus_target, a, b, a ** 3 - targets, b ** 3 - targets, active)
    assert roots[:3] == pytest.approx(targets[:3] ** (1.0 / 3.0), abs=1e-12)
    assert roots[3] == 2.0  # left at its bracket's end, as a single root finder would
