"""Tests for lenscompare.lenses.paraxial and .focus: first-order data and focusing.

Checked against the independent first-order values of the shared lens README
(optiland 0.6.3 and rayoptics, who agree to 1e-12 mm) and against textbook
formulas for lenses written here (tests/data/lenses/).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from lenscompare.errors import InputError
from lenscompare.lenses import (
    aperture_stop_index,
    closest_focus_distance_m,
    film_distance_mm,
    load_prescription,
    paraxial_data,
    parse_prescription,
    ray_transfer_matrix,
    stop_semi_aperture_for_f_number,
    stopped_down,
)

DATA = Path(__file__).parent / "data" / "lenses"

FIELDS = (
    "effective_focal_length_mm", "back_focal_length_mm", "front_principal_plane_mm",
    "rear_principal_plane_mm", "entrance_pupil_position_mm", "entrance_pupil_diameter_mm",
    "exit_pupil_position_mm", "exit_pupil_diameter_mm", "f_number", "total_track_mm",
)
# The table of shared/data/lenses/README.md, as printed (optiland + rayoptics).
REFERENCE = {
    "dgauss.50mm": "50.35817 36.10591 23.23572 17.78774 19.9465 24.8051 14.2686 26.5385 "
                   "2.0302 32.0400",
    "fisheye.10mm": "9.99142 23.16054 17.95628 46.61522 11.5424 2.5316 28.7022 7.0704 "
                    "3.9466 33.4461",
    "telephoto.250mm": "249.56661 105.07039 -83.13591 -41.71622 15.2865 46.0163 28.8692 "
                       "33.0014 5.4234 102.7800",
    "wide.22mm": "22.02350 14.31826 15.29362 25.66591 12.0887 8.2060 21.9152 9.6035 "
                 "2.6838 33.3711",
}


def _lens(name: str):
    return load_prescription(DATA / f"{name}.dat")


@pytest.mark.parametrize("name", sorted(REFERENCE))
def test_first_order_data_matches_the_shared_reference_table(name):
    data = paraxial_data(load_prescription(name))
    for field, printed in zip(FIELDS, REFERENCE[name].split()):
        # The table is rounded to its printed digits; within that, 1e-6 relative.
        decimals = len(printed.split(".")[1])
        tolerance = max(0.5 * 10.0 ** -decimals, 1e-6 * abs(float(printed))) * (1 + 1e-9)
        assert getattr(data, field) == pytest.approx(float(printed), abs=tolerance), field


@pytest.mark.parametrize("name", sorted(REFERENCE))
def test_cardinal_points_are_consistent(name):
    data = paraxial_data(load_prescription(name))
    f = data.effective_focal_length_mm
    rear_focal_point = data.total_track_mm + data.back_focal_length_mm
    assert data.rear_focal_point_mm == pytest.approx(rear_focal_point)
    assert data.rear_principal_plane_mm == pytest.approx(data.rear_focal_point_mm - f)
    assert data.front_principal_plane_mm == pytest.approx(data.front_focal_point_mm + f)
    assert data.front_focal_length_mm == -data.front_focal_point_mm
    assert data.f_number == pytest.approx(f / data.entrance_pupil_diameter_mm)
    assert all(math.isfinite(v) for v in vars(data).values())


def test_system_matrix_has_unit_determinant():
    for name in REFERENCE:
        assert np.linalg.det(ray_transfer_matrix(load_prescription(name))) == pytest.approx(1.0)


def test_thick_biconvex_singlet_matches_the_lensmaker_formula():
    # R1 = 50, R2 = -50, t = 8, n = 1.5, behind a stop 10 mm in front.
    n, r1, r2, t, vertex = 1.5, 50.0, -50.0, 8.0, 10.0
    power = (n - 1) * (1 / r1 - 1 / r2 + (n - 1) * t / (n * r1 * r2))
    f = 1 / power
    data = paraxial_data(_lens("biconvex_stop_front"))
    assert data.effective_focal_length_mm == pytest.approx(f, rel=1e-12)
    # Principal planes, from each vertex (Hecht, thick lens).
    assert data.front_principal_plane_mm == pytest.approx(vertex - f * (n - 1) * t / (n * r2))
    assert data.rear_principal_plane_mm == pytest.approx(vertex + t - f * (n - 1) * t / (n * r1))
    # The stop is in front of everything: it is its own entrance pupil.
    assert data.stop_index == 0
    assert data.entrance_pupil_position_mm == 0.0
    assert data.entrance_pupil_diameter_mm == 10.0
    # Exit pupil: the stop imaged by the thick lens, Gaussian form from H and H'.
    a = data.front_principal_plane_mm - 0.0  # stop distance in front of H
    b = 1 / (1 / f - 1 / a)  # image distance behind H' (negative: virtual)
    assert data.exit_pupil_position_mm == pytest.approx(data.rear_principal_plane_mm + b)
    assert data.exit_pupil_diameter_mm == pytest.approx(10.0 * abs(b / a))


def test_plano_convex_both_ways_round():
    # f = R / (n - 1) = 100 either way; one principal plane sits on the curved vertex.
    flat_front = paraxial_data(_lens("planoconvex_flat_front"))
    flat_back = paraxial_data(_lens("planoconvex_flat_back"))
    assert flat_front.effective_focal_length_mm == pytest.approx(100.0, rel=1e-12)
    assert flat_back.effective_focal_length_mm == pytest.approx(100.0, rel=1e-12)
    assert flat_front.rear_principal_plane_mm == pytest.approx(5.0)
    assert flat_front.back_focal_length_mm == pytest.approx(100.0)
    # The other principal plane is the curved vertex seen through the flat face
    # (apparent depth t / n).
    assert flat_front.front_principal_plane_mm == pytest.approx(5.0 / 1.5)
    assert flat_back.front_principal_plane_mm == pytest.approx(0.0, abs=1e-12)
    assert flat_back.rear_principal_plane_mm == pytest.approx(5.0 - 5.0 / 1.5)
    assert flat_back.front_focal_length_mm == pytest.approx(100.0)
    assert flat_back.back_focal_length_mm == pytest.approx(100.0 - 5.0 / 1.5)


def test_radius_1e9_behaves_like_a_plane():
    planar = paraxial_data(_lens("planoconvex_flat_front"))
    nearly = paraxial_data(_lens("planoconvex_nearly_flat_front"))
    for field in FIELDS:
        assert getattr(nearly, field) == pytest.approx(getattr(planar, field), rel=1e-6), field
        assert math.isfinite(getattr(nearly, field))


def test_zero_thickness_cemented_layer_changes_nothing():
    layered = paraxial_data(_lens("cemented_zero_layer"))
    plain = paraxial_data(_lens("singlet_no_layer"))
    for field in FIELDS:
        assert getattr(layered, field) == pytest.approx(getattr(plain, field), rel=1e-12), field


def test_without_a_marked_stop_the_limiting_surface_is_the_stop():
    # The small rear aperture limits a beam from infinity.
    lens = parse_prescription(b"50 5 1.5 30\n-50 0 1 10\n", source="t.dat", name="t")
    assert lens.stop_index is None
    assert aperture_stop_index(lens) == 1
    # Entrance pupil: the 10 mm rear rim seen through the front surface,
    # magnified by 1 / (1 - (t / n) * (n - 1) / R1).
    magnification = 1.0 / (1.0 - 5.0 / 1.5 * 0.5 / 50.0)
    assert paraxial_data(lens).entrance_pupil_diameter_mm == pytest.approx(10.0 * magnification)


def test_afocal_lens_is_refused():
    # Two powers of 1/16 mm^-1, 32 mm (reduced) apart: zero total power, exactly.
    lens = parse_prescription(b"8 48 1.5 8\n-8 0 1 8\n", source="t.dat", name="t")
    assert ray_transfer_matrix(lens)[1, 0] == 0.0
    with pytest.raises(InputError, match="afocal"):
        paraxial_data(lens)


@pytest.mark.parametrize("f_number", [2.8, 4.0, 16.0])
def test_stopping_down_gives_the_requested_f_number(f_number):
    lens = load_prescription("dgauss.50mm")
    smaller = stopped_down(lens, f_number)
    assert paraxial_data(smaller).f_number == pytest.approx(f_number, rel=1e-12)
    assert smaller.surfaces[5].semi_aperture_mm == stop_semi_aperture_for_f_number(lens, f_number)


def test_the_lens_own_f_number_is_allowed_and_faster_is_refused():
    lens = load_prescription("dgauss.50mm")
    own = paraxial_data(lens).f_number
    assert stop_semi_aperture_for_f_number(lens, own) == pytest.approx(8.55, rel=1e-12)
    with pytest.raises(InputError) as info:
        stop_semi_aperture_for_f_number(lens, 1.4, source="scene.toml", key="camera.f_number")
    assert str(info.value).startswith("scene.toml: camera.f_number: f/1.4 is faster")
    for bad in (0.0, -2.0, math.nan, math.inf, "f/2"):
        with pytest.raises(InputError, match="positive number"):
            stop_semi_aperture_for_f_number(lens, bad)


# --- focusing ---------------------------------------------------------------


@pytest.mark.parametrize("name", sorted(REFERENCE))
def test_focus_at_infinity_and_very_far_is_the_back_focal_length(name):
    lens = load_prescription(name)
    bfl = paraxial_data(lens).back_focal_length_mm
    assert film_distance_mm(lens, math.inf) == pytest.approx(bfl, rel=1e-15)
    assert film_distance_mm(lens, 1e12) == pytest.approx(bfl, rel=1e-9)
    assert film_distance_mm(lens, 1e300) == pytest.approx(bfl, rel=1e-15)


@pytest.mark.parametrize("distance_m", [0.5, 1.0, 3.0, 100.0])
def test_focus_matches_the_gaussian_lens_equation_from_the_principal_planes(distance_m):
    lens = load_prescription("dgauss.50mm")
    data = paraxial_data(lens)
    f = data.effective_focal_length_mm
    object_z = data.entrance_pupil_position_mm - 1000.0 * distance_m
    a = data.front_principal_plane_mm - object_z  # object distance in front of H
    b = 1.0 / (1.0 / f - 1.0 / a)  # image distance behind H'
    expected = data.rear_principal_plane_mm + b - data.total_track_mm
    assert film_distance_mm(lens, distance_m) == pytest.approx(expected, rel=1e-12)


def test_focus_moves_the_film_out_as_the_object_comes_closer():
    lens = load_prescription("wide.22mm")
    distances = [film_distance_mm(lens, d) for d in (math.inf, 10.0, 1.0, 0.3, 0.1)]
    assert distances == sorted(distances)


@pytest.mark.parametrize("name", sorted(REFERENCE))
def test_focus_closer_than_the_lens_can_reach_is_refused_with_the_closest_distance(name):
    lens = load_prescription(name)
    closest = closest_focus_distance_m(lens)
    data = paraxial_data(lens)
    # The limit is the front focal point or the front of the lens.
    limit_z = min(data.front_focal_point_mm, 0.0)
    assert closest == pytest.approx((data.entrance_pupil_position_mm - limit_z) / 1000.0)
    with pytest.raises(InputError) as info:
        film_distance_mm(lens, closest * 0.99)
    assert f"{closest:.4g} m" in str(info.value)
    assert math.isfinite(film_distance_mm(lens, closest * 1.01))


def test_telephoto_closest_focus_from_its_front_focal_point():
    # F lies 332.7 mm in front of the first vertex, the entrance pupil 15.3 mm behind.
    lens = load_prescription("telephoto.250mm")
    assert closest_focus_distance_m(lens) == pytest.approx(0.34799, abs=1e-5)
    with pytest.raises(InputError, match="cannot focus at 0.3 m"):
        film_distance_mm(lens, 0.3, source="scene.toml", key="camera.focus_distance")


@pytest.mark.parametrize("bad", [0.0, -1.0, math.nan, None])
def test_focus_distance_must_be_positive(bad):
    with pytest.raises(InputError, match="positive number of metres"):
        film_distance_mm(load_prescription("dgauss.50mm"), bad)


def test_a_negative_lens_cannot_be_focused():
    lens = parse_prescription(b"-50 5 1.5 20\n50 0 1 20\n", source="t.dat", name="t")
    assert paraxial_data(lens).effective_focal_length_mm < 0
    with pytest.raises(InputError, match="no real image"):
        film_distance_mm(lens, 1.0)
