"""Tests for lenscompare.lenses.glass and the dispersion it gives a prescription:
the contract's Cauchy fit, catalogue glasses, the file checks, per-wavelength
prescriptions and ``chromatic_focal_shift_mm`` against rayoptics."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from lenscompare.errors import InputError
from lenscompare.lenses import load_prescription, paraxial_data, parse_prescription
from lenscompare.lenses.glass import C_NM, D_NM, F_NM, AbbeGlass, CatalogueGlass, find_catalogue_glass
from lenscompare.lenses.paraxial import chromatic_focal_shift_mm

DATA = Path(__file__).parent / "data" / "lenses"
ABBE_LENSES = ["biconvex_bk7.abbe.dat", "cooke_triplet.abbe.dat", "dgauss_abbe.dat"]
CATALOGUE_LENSES = ["edmund_49847.glass.dat", "sasian_triplet.glass.dat", "telescope_triplet.glass.dat"]


def _parse(text: str):
    return parse_prescription(text.encode(), source="g.dat", name="g")


def test_abbe_glass_meets_the_contract_at_d_and_between_f_and_c():
    glass = AbbeGlass(n_d=1.62004, abbe_v_d=36.37)
    assert glass.index_at(D_NM) == pytest.approx(1.62004, abs=1e-15)
    assert glass.index_at(F_NM) - glass.index_at(C_NM) == pytest.approx(0.62004 / 36.37, rel=1e-12)
    assert glass.index_at(400.0) > glass.index_at(F_NM) > glass.index_at(C_NM) > glass.index_at(780.0)


def test_a_catalogue_glass_gives_the_schott_data_sheet_values():
    # Schott N-BK7 data sheet: n_d 1.51680, n_F 1.52238, n_C 1.51432 (5 decimals).
    glass = find_catalogue_glass("N-BK7")
    assert glass == CatalogueGlass("N-BK7", "Schott")
    assert glass.index_at(587.5618) == pytest.approx(1.51680, abs=5e-6)
    assert glass.index_at(486.1327) == pytest.approx(1.52238, abs=5e-6)
    assert glass.index_at(656.2725) == pytest.approx(1.51432, abs=5e-6)
    assert find_catalogue_glass("S-LAH66").catalogue == "Ohara"
    assert find_catalogue_glass("no-such-glass") is None


def test_the_fifth_column_becomes_the_surface_glass():
    lens = _parse("0 2 0 10\n50 5 1.5168 20 N-BK7\n-50 3 1 20\n40 4 1.62 20 36.37\n-80 0 1 20 0\n")
    glasses = [s.glass for s in lens.surfaces]
    assert glasses == [None, CatalogueGlass("N-BK7", "Schott"), None, AbbeGlass(1.62, 36.37), None]
    assert lens.disperses
    hash(lens)  # still a frozen value, usable as a cache key


@pytest.mark.parametrize("text, line, fragment", [
    ("50 5 1.52 20 N-BK7\n-50 0 1 20\n", 1, "n_d 1.520000 disagrees with N-BK7 (Schott)'s catalogue n_d 1.516800"),
    ("50 5 1.5168 20 N-BK8\n-50 0 1 20\n", 1, "unknown glass 'N-BK8'"),
    ("50 5 1.5168 20 N-BK8\n-50 0 1 20\n", 1, "near names: N-BK7"),
    ("50 5 1.5168 20\n-50 0 1 20 N-BK7\n", 2, "glass 'N-BK7' on a row whose medium is air"),
    ("50 5 1.5168 20 2O\n-50 0 1 20\n", 1, "5th column '2O' is neither an Abbe number nor a glass name"),
    ("50 5 1.5168 20 NaN\n-50 0 1 20\n", 1, "abbe_v_d is NaN"),
])
def test_bad_glass_is_refused_naming_the_line(text, line, fragment):
    with pytest.raises(InputError) as info:
        _parse(text)
    assert info.value.key == f"line {line}"
    assert fragment in str(info.value)


def test_the_n_d_path_is_untouched_and_a_wavelength_changes_only_the_glass():
    lens = load_prescription(DATA / "cooke_triplet.abbe.dat")
    plain = load_prescription(DATA / "cooke_triplet.abbe.dat")
    assert paraxial_data(lens) == paraxial_data(plain)
    at_d = lens.at_wavelength(D_NM)
    assert [s.n_after for s in at_d.surfaces] == pytest.approx([s.n_after for s in lens.surfaces], abs=1e-15)
    blue = lens.at_wavelength(F_NM)
    assert blue.wavelength_nm == F_NM and blue.sha256 == lens.sha256 and blue != lens
    assert [s.n_after > t.n_after for s, t in zip(blue.surfaces, lens.surfaces)] == [
        s.glass is not None for s in lens.surfaces]


def test_a_lens_without_glass_has_no_focal_shift():
    assert chromatic_focal_shift_mm(load_prescription("dgauss.50mm")) == 0.0


def test_a_singlet_focal_shift_is_minus_f_over_v():
    """Thin-lens textbook truth: f_F - f_C = -f / V_d (to the lens's thickness)."""
    lens = load_prescription(DATA / "biconvex_bk7.abbe.dat")
    f = paraxial_data(lens).effective_focal_length_mm
    assert chromatic_focal_shift_mm(lens) == pytest.approx(-f / 64.17, rel=0.03)


@pytest.mark.parametrize("name", ABBE_LENSES + CATALOGUE_LENSES)
def test_focal_shift_agrees_with_rayoptics(name):
    """Independent: rayoptics' paraxial BFL at F and C, its model built from the
    file's numbers by tests/rayoptics_models.py (not by our parser)."""
    pytest.importorskip("rayoptics")
    from rayoptics_models import back_focal_length_mm

    path = DATA / name
    theirs = back_focal_length_mm(path, wavelength_nm=F_NM) - back_focal_length_mm(path, wavelength_nm=C_NM)
    ours = chromatic_focal_shift_mm(load_prescription(path))
    assert ours < 0  # all these are undercorrected: blue focuses nearer
    assert ours == pytest.approx(theirs, rel=1e-6)


def test_lens_info_reports_the_focal_shift_and_the_glasses(main, capsys):
    path = DATA / "sasian_triplet.glass.dat"
    assert main(["lens", "info", str(path), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["chromatic_focal_shift_mm"] == chromatic_focal_shift_mm(load_prescription(path))
    assert info["glasses"][0] == {"surface": 1, "line": 6, "glass": "N-LAK9", "catalogue": "Schott"}
    assert main(["lens", "info", str(DATA / "cooke_triplet.abbe.dat")]) == 0
    out = capsys.readouterr().out
    assert "chromatic focal shift" in out and "1 V_d 60.32" in out


def test_a_bad_glass_is_exit_2_with_one_line(main, capsys, tmp_path):
    bad = tmp_path / "bad.dat"
    bad.write_text("# c\n50 5 1.52 20 N-BK7\n-50 0 1 20\n")
    assert main(["lens", "info", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"{bad}: line 2: n_d 1.520000 disagrees" in err and "1.516800" in err
