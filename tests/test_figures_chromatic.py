"""The chromatic teaching figure: ray fans at F, d and C and the focal shift
against wavelength, checked against ``lens info`` and paraxial optics."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from lenscompare.errors import InputError
from lenscompare.figures import chromatic_figure, chromatic_geometry
from lenscompare.figures.chromatic import LINES_NM, TEACHING_SINGLET, axis_crossing_z_mm, teaching_singlet
from lenscompare.lenses import load_prescription, paraxial_data

DATA = Path(__file__).parent / "data" / "lenses"


def drawn(figure, gid):
    return figure.findobj(lambda artist: artist.get_gid() == gid)


@pytest.mark.parametrize("lens", [None, DATA / "cooke_triplet.abbe.dat", DATA / "sasian_triplet.glass.dat"])
def test_the_plotted_f_minus_c_shift_is_lens_info_s(lens, main, capsys, tmp_path):
    prescription = teaching_singlet() if lens is None else load_prescription(lens)
    if lens is None:
        lens = tmp_path / "singlet.dat"
        lens.write_text(TEACHING_SINGLET)
    assert main(["lens", "info", str(lens), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    g = chromatic_geometry(prescription)
    figure = chromatic_figure(g)
    curve = drawn(figure, "focal-shift")[0]
    x, y = curve.get_xdata(), curve.get_ydata()
    assert x.min() <= 400.0 and x.max() >= 700.0
    shift = np.interp(LINES_NM["F"], x, y) - np.interp(LINES_NM["C"], x, y)
    assert shift == pytest.approx(info["chromatic_focal_shift_mm"], rel=1e-9)
    assert np.interp(LINES_NM["d"], x, y) == pytest.approx(0.0, abs=1e-12)
    assert shift < 0  # all three are undercorrected: blue focuses nearer


def test_the_fans_focus_where_paraxial_optics_puts_each_line():
    """The rays nearest the axis cross it F before d before C, as far apart as
    the paraxial foci (their spherical aberration, a quarter of the way out,
    is nearly the same at every line)."""
    g = chromatic_geometry()
    near = {}
    for name, paths in g.fans.items():
        assert len(paths) >= 9
        innermost = min(paths, key=lambda p: abs(p.points_mm[0, 1]) if p.points_mm[0, 1] != 0 else np.inf)
        near[name] = axis_crossing_z_mm(innermost)
        assert near[name] < g.paraxial_focus_z_mm[name]  # undercorrected spherical aberration
    assert near["F"] < near["d"] < near["C"]
    foci = g.paraxial_focus_z_mm
    assert near["F"] - near["C"] == pytest.approx(foci["F"] - foci["C"], rel=0.05)
    assert foci["F"] - foci["C"] == pytest.approx(g.chromatic_focal_shift_mm, rel=1e-12)
    singlet = teaching_singlet()
    assert g.paraxial_focus_z_mm["d"] == pytest.approx(singlet.total_track_mm
                                                       + paraxial_data(singlet).back_focal_length_mm, rel=1e-4)


def test_a_lens_that_does_not_disperse_is_refused():
    with pytest.raises(InputError, match="does not disperse"):
        chromatic_geometry(load_prescription("dgauss.50mm"))


def test_the_command_draws_a_chosen_lens_and_refuses_one_without_glass(main, capsys, tmp_path):
    out = tmp_path / "figs"
    assert main(["figures", "-o", str(out), "--no-svg", "--chromatic-lens", str(DATA / "cooke_triplet.abbe.dat")]) == 0
    assert (out / "chromatic.png").stat().st_size > 30_000
    capsys.readouterr()
    assert main(["figures", "-o", str(tmp_path / "none"), "--chromatic-lens", "dgauss.50mm"]) == 2
    err = capsys.readouterr().err
    assert "does not disperse" in err and err.count("\n") == 1
    assert not (tmp_path / "none").exists()
