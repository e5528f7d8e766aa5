"""Tests for lenscompare.lenses.prescription: reading and validating lens files."""

from __future__ import annotations

import hashlib
import math
from pathlib import Path

import pytest

from lenscompare.errors import InputError
from lenscompare.lenses import load_prescription, parse_prescription, sag_mm, shipped_lens_names

DATA = Path(__file__).parent / "data" / "lenses"
SHIPPED = Path(__file__).parents[1] / "lenscompare" / "lenses" / "data"
CLASSICS = ("dgauss.50mm", "fisheye.10mm", "telephoto.250mm", "wide.22mm")


def _parse(text: str):
    return parse_prescription(text.encode(), source="test.dat", name="test")


def _error(text: str) -> InputError:
    with pytest.raises(InputError) as info:
        _parse(text)
    return info.value


def test_the_four_classics_and_the_dispersive_landscape_lens_are_shipped():
    assert shipped_lens_names() == tuple(sorted(CLASSICS + ("landscape.125mm",)))


@pytest.mark.parametrize("name", CLASSICS)
def test_shipped_lens_loads_by_name_with_the_hash_of_its_file(name):
    prescription = load_prescription(name)
    data = (SHIPPED / f"{name}.dat").read_bytes()
    assert prescription.name == name
    assert prescription.sha256 == hashlib.sha256(data).hexdigest()
    assert sum(s.is_stop for s in prescription.surfaces) == 1


def test_double_gauss_rows_become_surfaces():
    lens = load_prescription("dgauss.50mm")
    assert len(lens.surfaces) == 11
    first, stop, last = lens.surfaces[0], lens.surfaces[5], lens.surfaces[-1]
    assert (first.radius_mm, first.thickness_mm, first.n_after, first.semi_aperture_mm) == (
        29.475, 3.76, 1.67, 12.6)
    assert first.line == 6  # five comment lines come first
    assert stop.is_stop and math.isinf(stop.radius_mm) and stop.n_after == 1.0
    assert stop.semi_aperture_mm == pytest.approx(8.55)
    assert lens.stop_index == 5
    assert last.thickness_mm == 0.0  # the last thickness is ignored
    assert lens.total_track_mm == pytest.approx(32.04, abs=1e-12)
    assert lens.n_before(0) == 1.0 and lens.n_before(1) == 1.67


def test_a_path_loads_and_the_abbe_column_is_read():
    lens = load_prescription(DATA / "cemented_zero_layer.dat")
    assert lens.name == "cemented_zero_layer"
    assert [s.abbe_v_d for s in lens.surfaces] == [30.0, 60.0, None]  # 0 means air


def test_inf_radius_is_a_plane():
    lens = load_prescription(DATA / "planoconvex_flat_front.dat")
    assert math.isinf(lens.surfaces[0].radius_mm) and not lens.surfaces[0].is_stop
    assert lens.surfaces[0].curvature_per_mm == 0.0
    assert lens.stop_index is None


def test_unknown_name_lists_the_shipped_lenses():
    with pytest.raises(InputError) as info:
        load_prescription("dgauss.85mm")
    assert "unknown lens" in str(info.value)
    assert all(name in str(info.value) for name in CLASSICS)


def test_unreadable_file_names_the_file(tmp_path):
    missing = tmp_path / "missing.dat"
    with pytest.raises(InputError) as info:
        load_prescription(missing)
    assert str(missing) in str(info.value) and "cannot read" in str(info.value)


def test_a_directory_is_unreadable(tmp_path):
    with pytest.raises(InputError, match="is a folder, expected a lens file"):
        load_prescription(tmp_path)


def test_binary_file_is_refused():
    with pytest.raises(InputError, match="not a text file"):
        parse_prescription(b"\xff\xfe\x00", source="x.dat", name="x")


@pytest.mark.parametrize("text", ["", "# only a comment\n\n   \n"])
def test_no_surfaces_is_refused(text):
    assert "no surfaces" in str(_error(text))


@pytest.mark.parametrize("text, line, fragment", [
    ("50 5 1.5\n", 1, "expected 4 or 5 columns"),
    ("50 5 1.5 20 40 7\n", 1, "found 6"),
    ("# c\n50 5 1.5 2O\n-50 0 1 20\n", 2, "'2O' is not a number"),
    ("50 5 1.5 20\n-50 0 1 1_0\n", 2, "is not a number"),
    ("50 nan 1.5 20\n-50 0 1 20\n", 1, "thickness_mm is NaN"),
    ("50 5 1.5 20\n-50 0 1 20 NaN\n", 2, "abbe_v_d is NaN"),
    ("50 inf 1.5 20\n-50 0 1 20\n", 1, "thickness_mm must be finite"),
    ("50 -1 1.5 20\n-50 0 1 20\n", 1, "thickness_mm must be finite and >= 0"),
    ("50 5 inf 20\n-50 0 1 20\n", 1, "n_d must be finite"),
    ("50 5 0.5 20\n-50 0 1 20\n", 1, "n_d 0.5 is below 1"),
    ("50 5 -1.5 20\n-50 0 1 20\n", 1, "below 1"),
    ("50 5 1.5 0\n-50 0 1 20\n", 1, "aperture_diameter_mm must be finite and > 0"),
    ("50 5 1.5 -20\n-50 0 1 20\n", 1, "aperture_diameter_mm"),
    ("50 5 1.5 inf\n-50 0 1 20\n", 1, "aperture_diameter_mm"),
    ("50 5 1.5 20 -3\n-50 0 1 20\n", 1, "abbe_v_d must be finite and >= 0"),
    ("9 5 1.5 20\n-50 0 1 20\n", 1, "|radius| 9 mm is smaller than the semi-aperture 10 mm"),
    ("50 5 1.5 20\n-9.99 0 1 20\n", 2, "smaller than the semi-aperture"),
    ("0 2 0 8\n50 5 1.5 20\n0 2 0 8\n-50 0 1 20\n", 3, "second aperture stop"),
    ("0 2 1.5 8\n50 5 1.5 20\n-50 0 1 20\n", 1, "stop (radius 0) must be followed by air"),
    ("50 2 1.5 20\n0 3 0 8\n-50 0 1 20\n", 2, "sits inside glass"),
    ("50 5 1.5 20\n-50 0 1.5 20\n", 2, "must leave the light in air"),
    # Biconvex, edge thickness negative: the surfaces cross inside the aperture.
    ("50 2 1.5 20\n-50 0 1 20\n", 1, "cross inside the aperture"),
    # Zero thickness, the steeper surface first: they cross right away.
    ("50 0 1.6 20\n80 5 1.5 20\n-50 0 1 20\n", 1, "cross inside the aperture"),
    # An air gap that closes before the rim.
    ("50 5 1.5 20\n-50 0.2 1 20\n-40 3 1.5 20\n80 0 1 20\n", 2, "line 3"),
])
def test_bad_rows_are_refused_with_file_and_line(text, line, fragment):
    error = _error(text)
    assert error.source == "test.dat"
    assert error.key == f"line {line}"
    assert fragment in str(error)
    assert str(error).startswith(f"test.dat: line {line}: ")


def test_the_last_thickness_is_ignored_but_must_be_a_number():
    lens = _parse("50 5 1.5 20\n-50 inf 1 20\n")
    assert lens.surfaces[-1].thickness_mm == 0.0
    assert _error("50 5 1.5 20\n-50 x 1 20\n").key == "line 2"


def test_comments_blank_lines_tabs_and_signs_are_accepted():
    lens = _parse("# header\n\n+50\t5\t1.5\t20  # trailing comment\n-5E1 0 0 2e1\n")
    assert [s.radius_mm for s in lens.surfaces] == [50.0, -50.0]
    assert lens.surfaces[1].n_after == 1.0  # n 0 is air


def test_surfaces_touching_at_the_rim_are_allowed():
    # Biconvex with zero edge thickness: centre thickness = twice the rim sag.
    rim_sag = sag_mm(1 / 50, 10.0)
    lens = _parse(f"50 {2 * rim_sag!r} 1.5 20\n-50 0 1 20\n")
    assert len(lens.surfaces) == 2
    # ...and a hair thinner they cross.
    assert "cross" in str(_error(f"50 {2 * rim_sag - 1e-6!r} 1.5 20\n-50 0 1 20\n"))


def test_zero_thickness_neighbours_that_only_touch_are_allowed():
    # Equal radii: they coincide; flatter first: they touch at the vertex only.
    assert len(_parse("50 0 1.7 20\n50 5 1.5 20\n-80 0 1 20\n").surfaces) == 3
    assert len(_parse("80 0 1.7 20\n50 5 1.5 20\n-80 0 1 20\n").surfaces) == 3


def test_radius_equal_to_the_semi_aperture_is_a_hemisphere_and_allowed():
    # Two hemispheres 20 mm apart touch at the rim: a ball lens.
    assert _parse("10 20 1.5 20\n-10 0 1 20\n").surfaces[0].radius_mm == 10


def test_sag_is_stable_for_nearly_flat_surfaces():
    assert sag_mm(1e-9, 10.0) == pytest.approx(5e-8, rel=1e-12)
    assert sag_mm(0.0, 10.0) == 0.0
    assert sag_mm(1 / 50, 10.0) == pytest.approx(50 - math.sqrt(50**2 - 10**2), rel=1e-12)
    assert sag_mm(-1 / 50, 10.0) == pytest.approx(-(50 - math.sqrt(50**2 - 10**2)), rel=1e-12)


def test_with_semi_aperture_returns_a_changed_copy():
    lens = load_prescription("dgauss.50mm")
    smaller = lens.with_semi_aperture(5, 4.0)
    assert smaller.surfaces[5].semi_aperture_mm == 4.0
    assert lens.surfaces[5].semi_aperture_mm == pytest.approx(8.55)
    assert smaller.sha256 == lens.sha256
    with pytest.raises(ValueError):
        lens.with_semi_aperture(5, -1.0)
