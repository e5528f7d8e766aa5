"""The shipped dispersive lens ``landscape.125mm`` (an N-BK7 meniscus behind
its stop): found by name, and its ``lens info --json`` chromatic focal shift
and focal length against rayoptics, whose model is built from the file's
numbers by tests/rayoptics_models.py (rayoptics' own N-BK7, not our parser)."""

from __future__ import annotations

import json
from importlib import resources

import pytest

from lenscompare.lenses import shipped_lens_names

F_NM, C_NM, D_NM = 486.13, 656.27, 587.56


def _path():
    return resources.files("lenscompare.lenses") / "data" / "landscape.125mm.dat"


def test_it_is_shipped_with_its_glass_named():
    assert "landscape.125mm" in shipped_lens_names()
    assert "N-BK7" in _path().read_text() and "Thorlabs LE1156-B" in _path().read_text()


def test_lens_info_focal_shift_and_focal_length_agree_with_rayoptics(main, capsys):
    pytest.importorskip("rayoptics")
    from rayoptics.parax.firstorder import compute_first_order
    from rayoptics_models import back_focal_length_mm, rayoptics_model

    assert main(["lens", "info", "landscape.125mm", "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    path = _path()
    theirs = back_focal_length_mm(path, wavelength_nm=F_NM) - back_focal_length_mm(path, wavelength_nm=C_NM)
    assert info["chromatic_focal_shift_mm"] < -1.0  # an uncorrected singlet: blue focuses nearer
    assert info["chromatic_focal_shift_mm"] == pytest.approx(theirs, rel=1e-6)
    opm = rayoptics_model(path, wavelength_nm=D_NM)
    _, _, first_order = compute_first_order(opm, opm["seq_model"].stop_surface, D_NM)
    assert info["effective_focal_length_mm"] == pytest.approx(first_order.efl, rel=1e-6)
    assert info["glasses"][0]["glass"] == "N-BK7"
