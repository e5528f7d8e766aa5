"""Tests for ``lenscompare lens info LENS [--json]`` (lenscompare.commands.lens)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest


DATA = Path(__file__).parent / "data" / "lenses"
REQUIRED = (
    "effective_focal_length_mm", "back_focal_length_mm", "front_principal_plane_mm",
    "rear_principal_plane_mm", "entrance_pupil_position_mm", "entrance_pupil_diameter_mm",
    "exit_pupil_position_mm", "exit_pupil_diameter_mm", "f_number",
)




def test_json_has_the_contract_keys_and_the_reference_values(main, capsys):
    assert main(["lens", "info", "dgauss.50mm", "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert set(REQUIRED) <= set(info)
    assert info["name"] == "dgauss.50mm"
    assert len(info["sha256"]) == 64
    # Values from the shared lens README (positions from the first vertex).
    assert info["effective_focal_length_mm"] == pytest.approx(50.35817, abs=5e-6)
    assert info["rear_principal_plane_mm"] == pytest.approx(17.78774, abs=5e-6)
    assert info["entrance_pupil_position_mm"] == pytest.approx(19.9465, abs=5e-5)
    assert info["exit_pupil_diameter_mm"] == pytest.approx(26.5385, abs=5e-5)
    assert info["f_number"] == pytest.approx(2.0302, abs=5e-5)
    assert info["total_track_mm"] == pytest.approx(32.04)
    assert info["closest_focus_m"] > 0
    assert info["stop_surface"] == 6


def test_json_is_one_line_of_strict_json(main, capsys):
    assert main(["lens", "info", "telephoto.250mm", "--json"]) == 0
    out = capsys.readouterr().out
    assert out.count("\n") == 1
    json.loads(out, parse_constant=lambda name: pytest.fail(f"non-JSON constant {name}"))


def test_table_lists_the_values_readably(main, capsys):
    assert main(["lens", "info", str(DATA / "planoconvex_flat_back.dat")]) == 0
    out = capsys.readouterr().out
    assert out.startswith("planoconvex_flat_back")
    assert "effective focal length" in out and "100.0000 mm" in out
    assert "positive toward the film" in out


def test_unknown_lens_is_exit_2_with_one_line(main, capsys):
    assert main(["lens", "info", "zoom.35mm"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "zoom.35mm: unknown lens name" in err and "dgauss.50mm" in err


def test_bad_lens_file_names_file_and_line(main, capsys, tmp_path):
    bad = tmp_path / "bad.dat"
    bad.write_text("# header\n50 5 1.5 20\n-50 0 1\n")
    assert main(["lens", "info", str(bad), "--json"]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert f"{bad}: line 3: expected 4 or 5 columns" in captured.err


def test_missing_sub_command_is_exit_2(main, capsys):
    assert main(["lens"]) == 2
    assert "required" in capsys.readouterr().err


def test_lens_info_function_gives_the_same_data(main):
    from lenscompare.lenses.info import lens_info
    from lenscompare.lenses import load_prescription, paraxial_data

    lens = load_prescription("wide.22mm")
    info = lens_info(lens)
    data = paraxial_data(lens)
    assert info["back_focal_length_mm"] == data.back_focal_length_mm
    assert info["sha256"] == lens.sha256
