"""Tests for the teaching figures (lenscompare.figures) and ``lenscompare figures``.

The drawings are checked by their geometry, not their pixels: the numbers a
figure draws come from the optics functions (thin-lens equations, paraxial
data, the real-ray trace), and the artists carry ``gid``s so that the tests
can read the coordinates actually handed to matplotlib.
"""

from __future__ import annotations

import contextlib
import json
import math
import struct
from pathlib import Path

import numpy as np
import pytest

from lenscompare import figures
from lenscompare.errors import ExternalError, InputError
from lenscompare.figures import (
    lens_system_figure,
    lens_system_geometry,
    thick_lens_figure,
    thick_lens_geometry,
    thin_lens_figure,
    thin_lens_geometry,
    write_teaching_figures,
)
from lenscompare.figures._lens_drawing import element_outlines_mm
from lenscompare.lenses import (
    film_distance_mm,
    load_prescription,
    paraxial_data,
    sag_mm,
    shipped_lens_names,
    trace_from_scene,
)
from lenscompare.optics import thin_lens as optics

DATA = Path(__file__).parent / "data" / "lenses"
ALL_LENSES = list(shipped_lens_names()) + [str(p) for p in sorted(DATA.glob("*.dat"))]
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _drawn(figure, gid):
    """The artists of a figure with this gid."""
    found = figure.findobj(lambda artist: artist.get_gid() == gid)
    assert found, f"nothing drawn with gid {gid!r}"
    return found


def _xy(line):
    return np.asarray(line.get_xdata(), dtype=float), np.asarray(line.get_ydata(), dtype=float)


def _png_size(data: bytes) -> tuple[int, int]:
    assert data[:8] == PNG_SIGNATURE and data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


# --------------------------------------------------------------------------- thin lens


THIN_CASES = [
    dict(),  # the defaults: f = 50 mm, f/2, focus 2 m, points at 1 m and 5 m
    dict(focal_length_mm=35.0, f_number=1.4, focus_distance_m=0.8, object_distances_m=(0.5, 3.0)),
    dict(focal_length_mm=85.0, f_number=4.0, focus_distance_m=10.0,
         object_distances_m=(2.0, 10.0, 40.0)),
]


@pytest.mark.parametrize("case", THIN_CASES)
def test_thin_lens_numbers_are_equations_2_to_9(case):
    g = thin_lens_geometry(**case)
    f, n = case.get("focal_length_mm", 50.0), case.get("f_number", 2.0)
    d = case.get("focus_distance_m", 2.0) * 1000.0
    assert g.aperture_diameter_mm == pytest.approx(optics.aperture_diameter_mm(f, n))
    assert g.film_distance_mm == pytest.approx(optics.focus_film_distance_mm(d, f))
    distances = sorted(x * 1000.0 for x in case.get("object_distances_m", (1.0, 5.0)))
    assert [p.object_distance_mm for p in g.points] == pytest.approx(distances)
    for point in g.points:
        l = point.object_distance_mm
        c = optics.circle_of_confusion_mm(l, focus_distance_mm=d, focal_length_mm=f,
                                          aperture_diameter_mm=g.aperture_diameter_mm)
        assert point.image_distance_mm == pytest.approx(optics.image_distance_mm(l, f))
        assert point.blur_diameter_mm == pytest.approx(c)
        assert point.blur_angle_rad == pytest.approx(optics.blur_angle_rad(c, g.film_distance_mm))
        assert point.defocus_diopters == pytest.approx(
            optics.defocus_diopters(point.image_distance_mm, g.film_distance_mm))


def test_thin_lens_default_values_by_hand():
    # f = 50, d = 2000: d' = 50 * 2000 / 1950; l = 1000: l' = 50000 / 950;
    # c = 25 (l' - d') / l' = 0.641026 mm (the thin_lens doctest); theta ~ c / d'.
    g = thin_lens_geometry()
    assert g.film_distance_mm == pytest.approx(100000.0 / 1950.0)
    near, far = g.points
    assert near.image_distance_mm == pytest.approx(50000.0 / 950.0)
    assert near.blur_diameter_mm == pytest.approx(0.641026, abs=5e-7)
    assert near.blur_angle_rad == pytest.approx(0.0125, rel=1e-4)
    assert far.image_distance_mm < g.film_distance_mm < near.image_distance_mm


@pytest.mark.parametrize("case", THIN_CASES)
def test_drawn_blur_disk_is_the_cone_at_the_film_and_equals_eq_5(case):
    # Similar triangles on the drawn cone edges (aperture edge -> image point)
    # give the same diameter as eq. 5's closed form.
    g = thin_lens_geometry(**case)
    figure = thin_lens_figure(g)
    (film,) = _drawn(figure, "film-zoom")
    assert np.allclose(_xy(film)[0], g.film_distance_mm)
    for i, point in enumerate(g.points, start=1):
        assert g.drawn_blur_diameter_mm(i - 1) == pytest.approx(point.blur_diameter_mm, rel=1e-9)
        (disk,) = _drawn(figure, f"blur-disk-{i}")
        x, y = _xy(disk)
        assert np.allclose(x, g.film_distance_mm)
        assert y.max() - y.min() == pytest.approx(point.blur_diameter_mm, rel=1e-9)
        (image,) = _drawn(figure, f"image-point-{i}")
        assert _xy(image)[0] == pytest.approx(point.image_distance_mm)


def test_drawn_cones_run_from_the_aperture_edges_to_the_image_points():
    g = thin_lens_geometry()
    figure = thin_lens_figure(g)
    half = g.aperture_diameter_mm / 2.0
    for i, point in enumerate(g.points, start=1):
        for cone in _drawn(figure, f"cone-{i}"):
            z, y = _xy(cone)
            assert z[0] == 0.0 and abs(y[0]) == pytest.approx(half)
            # Straight line through (0, +-a/2) and (l', 0), ending on the film.
            expected = y[0] * (1.0 - z / point.image_distance_mm)
            assert np.allclose(y, expected)
            assert z[-1] == pytest.approx(g.film_distance_mm)
    (f_prime,) = _drawn(figure, "F'")
    assert _xy(f_prime)[0] == pytest.approx(g.focal_length_mm)


@pytest.mark.parametrize("bad, key", [
    (dict(focal_length_mm=-50.0), "focal_length_mm"),
    (dict(f_number=float("nan")), "f_number"),
    (dict(focus_distance_m=0.04), "focus_distance_m"),  # inside f = 50 mm
    (dict(object_distances_m=(0.03, 5.0)), "object_distances_m"),
    (dict(object_distances_m=()), "object_distances_m"),
    (dict(object_distances_m=(1.0, 2.0, 3.0, 4.0)), "object_distances_m"),
])
def test_thin_lens_rejects_bad_parameters(bad, key):
    with pytest.raises(InputError) as error:
        thin_lens_geometry(**bad)
    assert error.value.key == key


# --------------------------------------------------------------------------- thick lens


@pytest.mark.parametrize("lens", ["dgauss.50mm", "telephoto.250mm", str(DATA / "thin_singlet.dat")])
def test_thick_lens_draws_cardinal_points_from_paraxial_data(lens):
    p = load_prescription(lens)
    data = paraxial_data(p)
    g = thick_lens_geometry(p)
    figure = thick_lens_figure(g)
    for gid, position in (("H", data.front_principal_plane_mm),
                          ("H'", data.rear_principal_plane_mm),
                          ("F", data.front_focal_point_mm), ("F'", data.rear_focal_point_mm)):
        (artist,) = _drawn(figure, gid)
        assert np.allclose(_xy(artist)[0], position)
    for i in range(len(g.real)):
        model = g.model_ray_mm(i)
        # Into H, across to H' parallel to the axis, out toward (F', -f tan alpha).
        assert model[1, 0] == pytest.approx(data.front_principal_plane_mm)
        assert model[2, 0] == pytest.approx(data.rear_principal_plane_mm)
        assert model[1, 1] == model[2, 1]
        assert (model[1, 1] - model[0, 1]) / (model[1, 0] - model[0, 0]) == pytest.approx(g.slope)
        z_f, y_f = g.focal_point_image_mm
        along = (z_f - model[2, 0]) / (model[3, 0] - model[2, 0])
        assert model[2, 1] + along * (model[3, 1] - model[2, 1]) == pytest.approx(y_f)
        (translation,) = _drawn(figure, f"model-translation-{i + 1}")
        assert np.allclose(np.column_stack(_xy(translation)), model[1:3])


def test_thick_lens_real_rays_are_the_trace_and_agree_with_the_model_for_a_thin_singlet():
    p = load_prescription(DATA / "thin_singlet.dat")
    g = thick_lens_geometry(p)
    z_f, y_f = g.focal_point_image_mm
    assert y_f == pytest.approx(-paraxial_data(p).effective_focal_length_mm
                                * math.tan(math.radians(g.field_angle_deg)))
    for path in g.real:
        assert path.passed
        start, end = path.points_mm[0], path.points_mm[-1]
        # The drawn exit segment is the ray trace_from_scene gives.
        direction = np.array([0.0, g.slope, 1.0])
        traced = trace_from_scene(p, [0.0, start[1], start[0]], direction)
        o, d = traced.origins_mm, traced.directions
        assert path.points_mm[-2] == pytest.approx([o[2], o[1]])
        assert end[1] == pytest.approx(o[1] + d[1] * (end[0] - o[2]) / d[2])
        # A thin singlet at a small aperture: real and model rays meet within 0.2 mm.
        y_at_focal_plane = o[1] + d[1] * (z_f - o[2]) / d[2]
        assert y_at_focal_plane == pytest.approx(y_f, abs=0.2)
    chief = g.real[1].points_mm  # through the centre of the stop, at the first vertex
    y_chief = chief[-2, 1] + (chief[-1, 1] - chief[-2, 1]) * (z_f - chief[-2, 0]) / (
        chief[-1, 0] - chief[-2, 0])
    assert y_chief == pytest.approx(y_f, abs=0.005)


# --------------------------------------------------------------------------- lens system


@pytest.mark.parametrize("lens", ALL_LENSES)
def test_lens_system_geometry_and_drawing(lens):
    p = load_prescription(lens)
    data = paraxial_data(p)
    g = lens_system_geometry(p, focus_distance_m=2.0)
    figure = lens_system_figure(g)

    # Film at the paraxial focus for 2 m.
    film_z = p.total_track_mm + film_distance_mm(p, 2.0)
    (film,) = _drawn(figure, "film")
    assert np.allclose(_xy(film)[0], film_z)

    # Exit pupil at its paraxial position and size.
    (pupil,) = _drawn(figure, "exit-pupil")
    z, y = _xy(pupil)
    assert np.allclose(z, data.exit_pupil_position_mm)
    assert y.max() == pytest.approx(data.exit_pupil_diameter_mm / 2.0)

    # The stop's blades start at its semi-aperture, at its vertex.
    if p.stop_index is not None:
        blades = _drawn(figure, "aperture-stop")
        assert len(blades) == 2
        for blade in blades:
            z, y = _xy(blade)
            assert np.allclose(z, p.vertex_z_mm[p.stop_index])
            assert np.abs(y).min() == pytest.approx(p.surfaces[p.stop_index].semi_aperture_mm)

    # Glass outlines lie on the surfaces' sag curves inside each clear aperture.
    for i, outline in element_outlines_mm(p):
        for index in (i, i + 1):
            surface = p.surfaces[index]
            on = np.isclose(outline[:, 0], p.vertex_z_mm[index]
                            + sag_mm(surface.curvature_per_mm,
                                     np.minimum(np.abs(outline[:, 1]), surface.semi_aperture_mm)))
            assert on.sum() >= 40  # the sampled profile

    for bundle in (g.axial, g.off_axis):
        passed = [path for path in bundle.paths if path.passed]
        blocked = [path for path in bundle.paths if not path.passed]
        assert len(passed) >= 3 and len(blocked) >= 1
        for path in passed:
            assert path.points_mm[-1, 0] == pytest.approx(film_z)
            assert len(path.points_mm) == len(p.surfaces) + 2
        for path in blocked:
            # Ends where it meets the blocking surface outside its clear
            # aperture (on a stop's blade, at an element's mount); a ray the
            # surface refuses inside its aperture (total internal reflection)
            # ends on the plane of that surface's rim.
            k = path.blocked_at
            assert len(path.points_mm) == k + 2
            (z0, y0), (z1, y1) = path.points_mm[:2]  # both on the incoming ray
            unclipped = trace_from_scene(p, [0.0, y0, z0], [0.0, y1 - y0, z1 - z0], clip=False,
                                         last=k)
            end = path.points_mm[-1]
            if unclipped.passed:
                assert end == pytest.approx(unclipped.origins_mm[[2, 1]])
                assert abs(end[1]) > p.surfaces[k].semi_aperture_mm
            else:
                assert end[0] == pytest.approx(p.vertex_z_mm[k] + sag_mm(
                    p.surfaces[k].curvature_per_mm, p.surfaces[k].semi_aperture_mm))


def test_lens_system_axial_bundle_focuses_on_the_film():
    # The double Gauss focused at 2 m: the axial bundle from 2 m meets the film
    # in a spot far smaller than the aperture (residual spherical aberration).
    g = lens_system_geometry(load_prescription("dgauss.50mm"), focus_distance_m=2.0)
    heights = g.axial.film_heights_mm
    assert np.abs(heights).max() < 0.1
    assert g.off_axis.field_angle_deg == pytest.approx(
        math.degrees(math.atan(0.7 * math.hypot(18, 12) / 50.358)), abs=0.05)


def test_lens_system_refuses_a_focus_the_lens_cannot_reach():
    with pytest.raises(InputError):
        lens_system_geometry(load_prescription("telephoto.250mm"), focus_distance_m=0.2)


# --------------------------------------------------------------------------- files


def test_write_teaching_figures_writes_valid_pngs_and_svgs(tmp_path):
    out = tmp_path / "new" / "figures"  # created with its parents
    written = write_teaching_figures(out)
    assert set(written) == {"thin_lens", "thick_lens", "lens_system", "aperture", "chromatic", "motion"}
    for name, path in written.items():
        assert path == out / f"{name}.png"
        data = path.read_bytes()
        width, height = _png_size(data)
        assert 1000 <= width <= 2500 and 300 <= height <= 1500, (name, width, height)
        assert 30_000 < len(data) < 3_000_000
        svg = path.with_suffix(".svg").read_text()
        assert svg.startswith("<?xml") and "<svg" in svg and svg.rstrip().endswith("</svg>")
    assert sorted(p.name for p in out.iterdir()) == sorted(
        f"{name}.{fmt}" for name in written for fmt in ("png", "svg"))  # no temporaries


def test_bad_lens_leaves_nothing(tmp_path):
    out = tmp_path / "figures"
    with pytest.raises(InputError, match="unknown lens name"):
        write_teaching_figures(out, lens="no-such-lens")
    assert not out.exists()


def _snapshot(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in folder.iterdir()}


def test_a_failure_while_drawing_keeps_the_old_figures(tmp_path, monkeypatch):
    write_teaching_figures(tmp_path, svg=False)
    before = _snapshot(tmp_path)

    def broken(geometry):
        raise RuntimeError("drawing failed")

    monkeypatch.setattr(figures, "lens_system_figure", broken)
    with pytest.raises(RuntimeError):
        write_teaching_figures(tmp_path, f_number=4.0, svg=False)
    assert _snapshot(tmp_path) == before


def test_a_failure_while_writing_leaves_no_file(tmp_path, monkeypatch):
    real = figures.atomic_output
    entered = []

    @contextlib.contextmanager
    def failing_on_the_fourth(path):
        entered.append(path)
        with real(path) as temporary:
            if len(entered) == 4:
                raise OSError("disk full")
            yield temporary

    monkeypatch.setattr(figures, "atomic_output", failing_on_the_fourth)
    out = tmp_path / "figures"
    with pytest.raises(ExternalError, match="disk full"):  # an OS error while writing: exit 1, one line
        write_teaching_figures(out)
    assert len(entered) == 4
    assert list(out.iterdir()) == []  # neither figures nor temporaries


def test_output_folder_that_is_a_file_is_an_input_error(tmp_path):
    target = tmp_path / "figures"
    target.write_text("not a folder")
    with pytest.raises(InputError, match="not a folder"):
        write_teaching_figures(target)


# --------------------------------------------------------------------------- command line




def test_command_writes_the_figures_for_a_user_lens(main, tmp_path, capsys):
    out = tmp_path / "figs"
    status = main(["figures", "-o", str(out), "--lens", str(DATA / "biconvex_stop_front.dat"),
                   "--focal-length-mm", "35", "--f-number", "2.8", "--focus-distance", "1.5",
                   "--object-distances", "0.7", "4", "--no-svg", "--json"])
    assert status == 0, capsys.readouterr().err
    report = json.loads(capsys.readouterr().out)
    assert set(report["figures"]) == {"thin_lens", "thick_lens", "lens_system", "aperture", "chromatic", "motion"}
    assert sorted(p.name for p in out.iterdir()) == ["aperture.png", "chromatic.png", "lens_system.png", "motion.png",
                                                     "thick_lens.png", "thin_lens.png"]


@pytest.mark.parametrize("argv, needle", [
    (["--lens", "no-such-lens"], "no-such-lens"),
    (["--lens", str(DATA / "missing.dat")], "missing.dat"),
    (["--focus-distance", "0.03"], "focus_distance_m"),
    (["--f-number", "-2"], "--f-number: expected a finite number > 0"),
    (["--object-distances", "1", "2", "3", "4"], "object_distances_m"),
])
def test_command_bad_input_exits_2_and_writes_nothing(main, tmp_path, capsys, argv, needle):
    out = tmp_path / "figs"
    assert main(["figures", "-o", str(out), *argv]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and needle in err and "Traceback" not in err
    assert not out.exists()
