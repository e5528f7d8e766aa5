"""Tests for ``lenscompare lens import FILE.zmx -o OUT.dat`` (lenscompare.lenses.zemax).

A real OpticStudio file (tests/data/zemax/README.md) is imported and its
first-order data compared with rayoptics' own for the same file; it renders
through the lens system.  Tiny hand-written files exercise the refusals.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from helpers import MINIMAL_SCENE

pytest.importorskip("rayoptics")

ZEMAX = Path(__file__).parent / "data" / "zemax"
DOUBLE_GAUSS = ZEMAX / "US00583336-2-scaled.zmx"

# A singlet in N-BK7, stop in front, entrance pupil 10 mm, fields 0 and 5 deg.
TINY = """\
VERS 140730 195 26155
MODE SEQ
NAME tiny singlet
UNIT MM X W X CM MR CPMM
ENPD 10
GCAT SCHOTT
XFLN 0 0
YFLN 0 5
WAVM 1 5.875618E-1 1
PWAV 1
SURF 0
  TYPE STANDARD
  CURV 0.0 0 0 0 0 ""
  DISZ INFINITY
SURF 1
  STOP
  TYPE STANDARD
  CURV 0.0 0 0 0 0 ""
  DISZ 5
SURF 2
  TYPE {type}
  CURV 0.02 0 0 0 0 ""
  DISZ 6
  GLAS {glass} 0 0 1.5168 6.417E+1 0 0 0 0 0 0
{extra}SURF 3
  TYPE STANDARD
  CURV -0.02 0 0 0 0 ""
  DISZ 95
SURF 4
  TYPE STANDARD
  CURV 0.0 0 0 0 0 ""
  DISZ 0
"""


def tiny(*, type="STANDARD", glass="N-BK7", extra="") -> str:
    return TINY.format(type=type, glass=glass, extra=extra)


def one_error_line(err: str) -> str:
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("lenscompare: error: ") and "Traceback" not in err, err
    return lines[0]


@pytest.fixture(scope="module")
def imported_double_gauss(tmp_path_factory):
    from lenscompare import cli

    out = tmp_path_factory.mktemp("zmx") / "dgauss_zmx.dat"
    assert cli.main(["lens", "import", str(DOUBLE_GAUSS), "-o", str(out)]) == 0
    return out


def rayoptics_first_order(path: Path):
    """rayoptics' own reading of the file: (first-order data, paraxial rays, total track)."""
    from rayoptics.zemax import zmxread

    from lenscompare.lenses.zemax import _no_log_file

    _no_log_file(zmxread)  # no zmx_read_lens.log in the working folder
    opm, _ = zmxread.read_lens(None, path.read_text())
    parax = opm["analysis_results"]["parax_data"]
    sm = opm["seq_model"]
    track = sum(gap.thi for gap in sm.gaps[1:-1])
    return parax.fod, parax, track


def test_imported_lens_keeps_glass_names_and_the_stop(imported_double_gauss):
    rows = [line.split() for line in imported_double_gauss.read_text().splitlines() if not line.startswith("#")]
    assert len(rows) == 12  # Zemax surfaces 1..12 (object and image dropped)
    assert [row[4] for row in rows if len(row) == 5] == ["N-BAK1", "N-BAK1", "N-BALF4", "N-BALF4", "N-BAK1", "N-BAK1"]
    assert rows[6][0] == "0"  # Zemax surface 7 is the stop
    assert float(rows[1][3]) == pytest.approx(2 * 6.3)  # DIAM kept (a fixed semi-diameter)
    assert float(rows[7][3]) == pytest.approx(2 * 4.5)  # DIAM kept (a pickup)


def test_imported_first_order_data_matches_rayoptics(imported_double_gauss, main, capsys):
    """Independent: rayoptics reads the same .zmx; object at infinity there is 1e10 mm."""
    assert main(["lens", "info", str(imported_double_gauss), "--json"]) == 0
    ours = json.loads(capsys.readouterr().out)
    fod, parax, track = rayoptics_first_order(DOUBLE_GAUSS)
    assert ours["total_track_mm"] == pytest.approx(track, rel=1e-12)
    pairs = {
        "effective_focal_length_mm": fod.efl,
        "back_focal_length_mm": fod.bfl,
        "front_principal_plane_mm": fod.pp1,
        "rear_principal_plane_mm": track + fod.ppk,
        "entrance_pupil_position_mm": fod.enp_dist,
        "entrance_pupil_diameter_mm": 2 * fod.enp_radius,
        "exit_pupil_diameter_mm": 2 * fod.exp_radius,
        "f_number": fod.fno,
    }
    for key, theirs in pairs.items():
        assert ours[key] == pytest.approx(theirs, rel=1e-6), key
    # Exit pupil: where rayoptics' paraxial chief ray crosses the axis behind the last surface.
    height, slope = parax.pr_ray[-2][0], parax.pr_ray[-2][1]
    assert ours["exit_pupil_position_mm"] == pytest.approx(track - height / slope, rel=1e-6)


def test_the_imported_lens_renders_through_the_lens_system(imported_double_gauss, tmp_path, main):
    from lenscompare.image import read_exr

    scene = tmp_path / "s.toml"
    scene.write_text(MINIMAL_SCENE.replace('model = "thin"', f'model = "lens"\nlens = "{imported_double_gauss}"')
                     .replace("f_number = 2.8", "f_number = 5.6"))
    assert main(["render", str(scene), "-o", str(tmp_path / "o.exr")]) == 0
    image = read_exr(tmp_path / "o.exr")
    pixels = np.asarray(image.pixels)
    assert np.isfinite(pixels).all() and pixels.mean() > 0.05


def test_semi_diameters_missing_from_the_file_are_computed(tmp_path, main, capsys):
    zmx = tmp_path / "tiny.zmx"
    zmx.write_text(tiny())
    out = tmp_path / "tiny.dat"
    assert main(["lens", "import", str(zmx), "-o", str(out)]) == 0
    assert capsys.readouterr().out == f"wrote {out}\n"
    rows = [line.split() for line in out.read_text().splitlines() if not line.startswith("#")]
    assert rows[0][0] == "0" and float(rows[0][3]) == pytest.approx(10.0, rel=1e-9)  # the ENPD 10 stop
    # Boundary rays of the 5 deg field reach above the axial 5 mm on the lens.
    assert all(float(row[3]) > 10.0 for row in rows[1:])
    assert rows[1][4] == "N-BK7"
    assert main(["lens", "info", str(out), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["chromatic_focal_shift_mm"] < 0


@pytest.mark.parametrize("kind, text, words", [
    ("conic", tiny(extra="  CONI -1.0\n"), "surface 2: conic constant -1: only spheres"),
    ("mirror", tiny(glass="MIRROR"), "surface 2: a mirror cannot be imported"),
    ("asphere", tiny(type="EVENASPH"), "surface 2: surface type EVENASPH cannot be imported"),
    ("coordinate break", tiny(type="COORDBRK"), "surface 2: a coordinate break"),
    ("gradient index", tiny(type="GRINSUR1"), "surface 2: surface type GRINSUR1 cannot be imported"),
    ("unknown glass", tiny(glass="N-BK8"), "surface 2: glass 'N-BK8' is not in the Schott"),
    ("not zemax", "hello\n", "no SURF records"),
    ("surfaces cross", tiny().replace("DISZ 6", "DISZ 0.1"), "surface 2: not representable as a lens file: this "
     "surface and the next one (surface 3) cross"),
    ("non-sequential", "MODE NSC\nSURF 0\n", "non-sequential"),
])
def test_what_a_lens_file_cannot_hold_is_refused_naming_the_surface(tmp_path, main, capsys, kind, text, words):
    zmx = tmp_path / "bad.zmx"
    zmx.write_text(text)
    out = tmp_path / "out.dat"
    out.write_text("a good old file\n")
    assert main(["lens", "import", str(zmx), "-o", str(out)]) == 2
    line = one_error_line(capsys.readouterr().err)
    assert f"{zmx}: " in line and words in line, line
    assert out.read_text() == "a good old file\n"  # never overwritten by a failed run
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.zmx", "out.dat"]  # no temporary left


def test_no_log_file_is_left_in_the_working_folder(tmp_path, monkeypatch, main):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "t.zmx").write_text(tiny(extra="  FOOB 1\n"))  # an unknown record: rayoptics logs it
    assert main(["lens", "import", "t.zmx", "-o", "t.dat"]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.dat", "t.zmx"]


def test_a_missing_or_binary_file_is_exit_2(tmp_path, main, capsys):
    assert main(["lens", "import", str(tmp_path / "nope.zmx"), "-o", str(tmp_path / "o.dat")]) == 2
    assert "nope.zmx" in one_error_line(capsys.readouterr().err)
    binary = tmp_path / "b.zmx"
    binary.write_bytes(b"\x00\x01\x02SURF 1\n")
    assert main(["lens", "import", str(binary), "-o", str(tmp_path / "o.dat")]) == 2
    assert "not a text file" in one_error_line(capsys.readouterr().err)
