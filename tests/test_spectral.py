"""Spectral renders ([render] spectral = true): the colour pipeline is neutral,
dispersion focuses each wavelength where the paraxial trace says, and the
guarantees of RGB renders (determinism, no NaN) hold."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from helpers import white_points_text
from lenscompare import _native
from lenscompare.cameras import camera_for
from lenscompare.errors import InputError
from lenscompare.lenses import load_prescription, paraxial_data
from lenscompare.lenses.glass import C_NM, D_NM, F_NM
from lenscompare.lenses.paraxial import chromatic_focal_shift_mm
from lenscompare.render import render
from lenscompare.scene import load_scene
from lenscompare.spectral import film_table, wavelength_distribution

SCENES = Path(__file__).parent.parent / "reference_scenes"
LENSES = Path(__file__).parent / "data" / "lenses"


def _scene(tmp_path, text: str, name: str = "s.toml"):
    path = tmp_path / name
    path.write_text(text)
    return load_scene(path)


def test_spectral_is_off_by_default_and_read_from_the_render_table(tmp_path):
    assert load_scene(SCENES / "showcase.toml").render.spectral is False
    text = (SCENES / "showcase.toml").read_text().replace("seed = 0", "seed = 0\nspectral = true")
    assert _scene(tmp_path, text).render.spectral is True


@pytest.mark.parametrize("value", ["2", '"yes"'])
def test_a_bad_spectral_value_is_refused(tmp_path, value):
    text = (SCENES / "showcase.toml").read_text().replace("seed = 0", f"seed = 0\nspectral = {value}")
    with pytest.raises(InputError, match="spectral"):
        _scene(tmp_path, text)


@pytest.mark.parametrize("nm", [300, 900])
def test_an_emitter_wavelength_outside_380_780_nm_is_refused(tmp_path, nm):
    text = (SCENES / "showcase.toml").read_text().replace(
        'color = [4.0, 3.2, 1.8]', f'color = [4.0, 3.2, 1.8]\nwavelength_nm = {nm}')
    with pytest.raises(InputError, match="wavelength_nm"):
        _scene(tmp_path, text)


def test_equal_energy_white_reads_one_in_every_channel():
    # Each channel's film response integrates to 1 over 380-780 nm (trapezoid rule).
    assert np.allclose(np.trapezoid(film_table(), dx=1.0, axis=0), 1.0, rtol=1e-12)


def test_the_wavelength_density_gives_half_to_the_lines():
    lines = (486.13, 656.27)
    edges, p = wavelength_distribution(lines)
    assert p.sum() == pytest.approx(1.0)
    in_band = [any(lo >= line - 0.5 - 1e-9 and hi <= line + 0.5 + 1e-9 for line in lines)
               for lo, hi in zip(edges[:-1], edges[1:])]
    # Half to the bands, plus the continuum's own share of their 2 nm
    assert 0.5 < p[in_band].sum() < 0.51
    # Without lines the density follows the film: more probability at 550 nm than at 400 nm
    edges, p = wavelength_distribution([])
    density = p / np.diff(edges)
    assert density[np.searchsorted(edges, 550.0) - 1] > 10 * density[np.searchsorted(edges, 400.0) - 1]


@pytest.mark.parametrize("sample_wavelengths", [False, True])  # integrated (the default here) and drawn
@pytest.mark.parametrize("name", ["flat_field", "showcase"])
def test_spectral_renders_match_rgb_in_every_channel_mean(name, sample_wavelengths):
    """Mallett-Yuksel spectra through the CIE 1931 film give the RGB back:
    channel means within 1 % (the issue's round trip; measured 0.02 %)."""
    scene = load_scene(SCENES / f"{name}.toml")
    rgb = render(scene, spp=32, progress=False).pixels.reshape(-1, 3).mean(axis=0)
    spectral = render(scene, spp=32, spectral=True, sample_wavelengths=sample_wavelengths,
                      progress=False).pixels.reshape(-1, 3).mean(axis=0)
    assert np.all(np.abs(spectral / rgb - 1.0) < 0.01), (rgb, spectral)


def test_rgb_renders_are_unchanged_when_wavelengths_exist():
    # Drawing wavelengths changes no film, lens or time point, for every sampler.
    for sampler in (_native.SAMPLER_RANDOM, _native.SAMPLER_JITTERED, _native.SAMPLER_REGULAR,
                    _native.SAMPLER_POISSON, _native.SAMPLER_SOBOL):
        spp = 64
        plain = [np.zeros((spp, 2), np.float32), np.zeros((spp, 2), np.float32), np.zeros(spp, np.float32)]
        both = [np.zeros((spp, 2), np.float32), np.zeros((spp, 2), np.float32), np.zeros(spp, np.float32)]
        wavelength = np.zeros(spp, np.float32)
        _native.diagnostics.pixel_samples(sampler, 7, 123, *plain)
        _native.diagnostics.pixel_samples(sampler, 7, 123, *both, wavelength=wavelength)
        for a, b in zip(plain, both):
            assert np.array_equal(a, b)
        # One wavelength per stratum [k/spp, (k+1)/spp) (random: independent, as its times)
        if sampler != _native.SAMPLER_RANDOM:
            assert sorted(np.floor(wavelength * spp).astype(int)) == list(range(spp)), sampler
        assert not np.array_equal(wavelength, plain[2])


@pytest.mark.parametrize("model", ["lens", "thin"])  # both carry bands of the spectrum on their rays
def test_spectral_renders_do_not_depend_on_the_thread_count(tmp_path, model):
    scene = _dispersive_showcase(tmp_path, model=model)
    one = render(scene, spp=4, spectral=True, threads=1, progress=False)
    two = render(scene, spp=4, spectral=True, threads=2, progress=False)
    assert np.array_equal(one.pixels, two.pixels)


@pytest.mark.parametrize("traced", [1, 2])
def test_fewer_traced_wavelengths_keep_the_lens_systems_colour(tmp_path, traced):
    """Tracing 1 or 2 of the four hero wavelengths (each still drawn from the
    density, weighted by its own pdf) is unbiased: the channel means of the
    dispersive lens system match the 4-wavelength render within 1 % (72x48,
    16 spp, five seeds: within 0.21 % for 2 and 0.61 % for 1). A wrong weight
    (1/4 for 1/n) or a wrong pdf would miss by far more."""
    scene = _dispersive_showcase(tmp_path, model="lens")
    means = {n: render(scene, spp=16, spectral=True, traced_wavelengths=n, sample_wavelengths=True,
                       progress=False).pixels.reshape(-1, 3).mean(axis=0) for n in (traced, 4)}
    assert np.all(np.abs(means[traced] / means[4] - 1.0) < 0.01), means


def test_the_lens_system_traces_the_hero_and_its_antipode_when_wavelengths_are_drawn(tmp_path):
    # bench/bench_spectral.py: 2 traced wavelengths reach 1 % RMSE sooner than 1 or 4. By default
    # the lens system's rays carry bands of the spectrum instead (tests/test_lens_bands.py).
    scene = _dispersive_showcase(tmp_path, model="lens")
    lens = render(scene, spp=1, spectral=True, sample_wavelengths=True, progress=False)
    assert lens.metadata["spectral"]["secondaries"] == "hero and antipode traced, others terminated"
    assert lens.metadata["spectral"]["wavelengths_sampled"]
    bands = render(scene, spp=1, spectral=True, progress=False)
    assert bands.metadata["spectral"]["secondaries"] == "none: a ray per stretch of the spectrum landing in one pixel"
    thin = render(_dispersive_showcase(tmp_path, model="thin"), spp=1, spectral=True, sample_wavelengths=True,
                  progress=False)
    assert thin.metadata["spectral"]["secondaries"] == "on the hero's ray where it is theirs, else traced"


def test_a_traced_wavelength_count_other_than_1_2_4_is_refused(tmp_path):
    with pytest.raises(ValueError, match="1, 2 or 4"):
        render(_dispersive_showcase(tmp_path, model="lens"), spp=1, spectral=True, traced_wavelengths=3,
               progress=False)


def test_total_internal_reflection_per_wavelength_gives_no_nan(tmp_path):
    # The TIR prism with an Abbe number: rays near the rim reflect totally at some wavelengths.
    lens = tmp_path / "tir.dat"
    lens.write_text("10 8 1.9 19 20\ninf 0 1 19\n")
    text = (SCENES / "showcase.toml").read_text().replace(
        'model = "thin"', f'model = "lens"\nlens = "{lens}"').replace("focal_length_mm = 50.0\n", "") \
        .replace("f_number = 2.8\n", "").replace("resolution = [360, 240]", "resolution = [60, 40]")
    scene = _scene(tmp_path, text)
    image = render(scene, spp=8, spectral=True, progress=False)
    assert np.isfinite(image.pixels).all()
    assert image.pixels.max() > 0.0


def _dispersive_flat_field(tmp_path, f_number: float):
    text = (SCENES / "flat_field.toml").read_text().replace(
        'model = "thin"', f'model = "lens"\nlens = "{LENSES / "dgauss_abbe.dat"}"') \
        .replace("focal_length_mm = 50.0\n", "").replace("f_number = 2.1", f"f_number = {f_number!r}")
    return render(_scene(tmp_path, text, name=f"f{f_number:g}.toml"), spp=256, spectral=True, progress=False)


@pytest.mark.parametrize("f_number", [64.0, 1000.0])
def test_a_dispersive_lens_behind_a_pinpoint_stop_keeps_the_flat_fields_colour(tmp_path, f_number):
    """Behind a small stop lateral colour moves the blue and red pupils off the 587 nm one by more
    than their size; sampled from the 587 nm pupil's polygon alone, the flat field read blue 0.675
    against red 0.912 over the image at f/1000 (the corner 0.096 against 0.833), and blue 1.3 %
    low against red at f/64. Each channel's mean now keeps its ratio to the others' at f/16, where
    the pupils overlap (the f-number moves no colour: blue reads 1 % above red, the lens's shorter
    focal length in blue)."""
    reference = _dispersive_flat_field(tmp_path, 16.0).pixels.reshape(-1, 3).mean(axis=0)
    image = _dispersive_flat_field(tmp_path, f_number)
    means = image.pixels.reshape(-1, 3).mean(axis=0)
    np.testing.assert_allclose(means / means[1], reference / reference[1], atol=0.005)
    centre = image.pixels[50:70, 80:100].reshape(-1, 3).mean(axis=0)
    assert np.all(np.abs(centre - 1.0) < 0.02), centre


def _dispersive_showcase(tmp_path, *, model: str):
    text = (SCENES / "showcase.toml").read_text().replace(
        'model = "thin"', f'model = "{model}"\nlens = "{LENSES / "dgauss_abbe.dat"}"') \
        .replace("focal_length_mm = 50.0\n", "").replace("resolution = [360, 240]", "resolution = [72, 48]")
    return _scene(tmp_path, text)


def _point_source_scene(tmp_path, wavelength_nm: float, *, f_number: float, film_mm: float, px: int):
    """A small monochromatic sphere 1 km away on the axis, black around it."""
    return _scene(tmp_path, f"""
[camera]
model = "lens"
lens = "{LENSES / 'biconvex_bk7.abbe.dat'}"
f_number = {f_number}
position = [0.0, 0.0, 0.0]
look_at = [0.0, 0.0, 1.0]
focus_distance = 1000.0
film_mm = [{film_mm}, {film_mm}]
resolution = [{px}, {px}]

[render]
spp = 64
sampler = "sobol"

[background]
color = [0.0, 0.0, 0.0]

[materials.line]
type = "emissive"
color = [1.0, 1.0, 1.0]
wavelength_nm = {wavelength_nm}

[[objects]]
type = "sphere"
center = [0.0, 0.0, 1000.0]
radius = 0.02
material = "line"
""", name=f"point_{wavelength_nm}.toml")


def _rms_spot_mm2(image, film_mm: float) -> float:
    """Second moment of the image's luminance about its centroid, mm^2."""
    y = image.pixels @ np.array([0.2126, 0.7152, 0.0722])
    h, w = y.shape
    pitch = film_mm / w
    yy, xx = np.mgrid[0:h, 0:w] * pitch
    total = y.sum()
    cx, cy = (y * xx).sum() / total, (y * yy).sum() / total
    return float((y * ((xx - cx) ** 2 + (yy - cy) ** 2)).sum() / total)


def test_rendered_focus_per_wavelength_follows_the_chromatic_focal_shift(tmp_path):
    """Monochromatic point sources at F, d and C through a singlet of N-BK7
    (V_d 64.17): the film position of the smallest rendered spot, per
    wavelength, against the paraxial trace. The spot's second moment is
    exactly quadratic in the film position (every ray's film point moves
    linearly with it), so a parabola through a through-focus series finds its
    minimum. At f/32 the real-ray best focus is the paraxial one to 0.2 %
    (measured; at f/16 spherochromatism already moves F - C by 2.7 %)."""
    lens = load_prescription(LENSES / "biconvex_bk7.abbe.dat")
    expected_mm = chromatic_focal_shift_mm(lens)  # -1.54 mm: blue focuses nearer
    film_mm, px = 0.2, 64
    best = {}
    for nm in (F_NM, D_NM, C_NM):
        scene = _point_source_scene(tmp_path, nm, f_number=32, film_mm=film_mm, px=px)
        camera = camera_for(scene, "lens")
        # The sphere's paraxial image at this wavelength, then a series through it.
        centre_mm = camera.film_z_mm + (paraxial_data(lens.at_wavelength(nm)).back_focal_length_mm
                                        - paraxial_data(lens).back_focal_length_mm)
        offsets_mm = np.linspace(-0.5, 0.5, 5)
        moments = []
        for dz in offsets_mm:
            moved = dataclasses.replace(camera, film_z_mm=centre_mm + dz)
            moments.append(_rms_spot_mm2(render(scene, camera=moved, spectral=True, progress=False), film_mm))
        a, b, _ = np.polyfit(centre_mm + offsets_mm, moments, 2)
        best[nm] = -b / (2 * a)
    rendered_mm = best[F_NM] - best[C_NM]
    assert rendered_mm == pytest.approx(expected_mm, rel=0.02)
    assert best[F_NM] < best[D_NM] < best[C_NM]


def test_thin_lens_blur_per_wavelength_follows_its_plane_of_focus(tmp_path):
    """Monochromatic points at F and C, 1 km away, through the thin lens
    derived from an N-BK7 singlet focused there in d light: each renders as
    the uniform disk its own plane of focus predicts, radius
    r_lens |1/focus(λ) - 1/D| on the screen, second moment r^2 / 2 over the
    d line's (second moments add: the d image is the point's own size and
    the pixels'). A secondary wavelength rides on the hero's ray only where
    that ray is its own (render_tile_spectral.h); riding it anywhere else
    would draw its disk at the hero's focus. Measured at 1024 spp: F 0.992,
    C 0.999 of the prediction."""
    from lenscompare.render_spectral import inverse_focus_per_m
    from lenscompare.spectral import wavelengths_nm

    film_mm, px, distance_m = 0.24, 96, 1000.0
    moment_mm2, radius_mm = {}, {}
    for nm in (D_NM, F_NM, C_NM):
        text = Path(_point_source_scene(tmp_path, nm, f_number=8, film_mm=film_mm, px=px).source).read_text()
        scene = _scene(tmp_path, text.replace('model = "lens"', 'model = "thin"'), name=f"thin_{nm}.toml")
        camera = camera_for(scene, "thin")
        inverse = inverse_focus_per_m(scene.camera.lens, film_distance_mm=camera.film_distance_mm,
                                      focal_length_mm=camera.focal_length_mm)
        screen_radius = (camera.aperture_diameter_mm / 2e3) * abs(
            np.interp(nm, wavelengths_nm(), inverse) - 1.0 / distance_m)
        radius_mm[nm] = screen_radius * camera.film_distance_mm
        moment_mm2[nm] = _rms_spot_mm2(render(scene, spectral=True, spp=1024, progress=False), film_mm)
    for nm in (F_NM, C_NM):
        assert radius_mm[nm] / (film_mm / px) > 5  # a disk several pixels wide
        assert moment_mm2[nm] - moment_mm2[D_NM] == pytest.approx(radius_mm[nm] ** 2 / 2, rel=0.03), nm


# A flint singlet (n_d 1.62004, V_d 36.37: Schott F2's data sheet values)
# 30 mm behind its stop: strong lateral colour.
STOP_AHEAD_F2 = "# radius thickness n_d aperture V_d\n0 30 0 10\n124 5 1.62004 30 36.37\n-124 0 1 30\n"


def _chief_ray_film_x_mm(lens, nm: float, angle_deg: float, film_z_mm: float) -> float:
    """|Film height| of the real chief ray at nm, on the fixed film plane."""
    import math

    from lenscompare.lenses.analysis import _chief_ray
    from lenscompare.lenses.trace import trace_from_scene

    at = lens.at_wavelength(nm)
    origin, direction = _chief_ray(at, math.radians(angle_deg), math.inf)
    ray = trace_from_scene(at, origin, direction, clip=False)
    o, d = ray.origins_mm, ray.directions
    return abs(float(o[1] + d[1] * (film_z_mm - o[2]) / d[2]))


def test_rendered_lateral_colour_follows_the_chief_ray(tmp_path):
    """A white point at 4 and 8 degrees: the blue-minus-red distance of the
    per-channel centroids against the chief ray's film height per wavelength,
    weighted by each channel's CIE 1931 response (the white's spectrum is 1);
    within 10 % (the issue's goal)."""
    import math

    from lenscompare.spectral import wavelengths_nm

    lens_path = tmp_path / "f2_stop_ahead.dat"
    lens_path.write_text(STOP_AHEAD_F2)
    angles_deg = (4.0, 8.0)
    film_w_mm, film_h_mm, width_px = 32.0, 0.8, 1600
    scene = _scene(tmp_path, white_points_text(lens_path, angles_deg=angles_deg, film_mm=(film_w_mm, film_h_mm),
                                               width_px=width_px, spp=256))
    camera = camera_for(scene, "lens")
    image = render(scene, spectral=True, progress=False).pixels
    pitch_mm = film_w_mm / width_px
    # The image is inverted: a point to the camera's right (+x) lands on the left half.
    x_mm = (width_px / 2 - (np.arange(width_px) + 0.5)) * pitch_mm
    lens = camera.prescription
    grid_nm = wavelengths_nm()[::5]
    weights = film_table()[::5]
    for angle in angles_deg:
        expected_x = np.array([_chief_ray_film_x_mm(lens, nm, angle, camera.film_z_mm) for nm in grid_nm])
        window = np.abs(np.abs(x_mm) - expected_x.mean()) < 0.6
        columns = image.sum(axis=0)[window]  # (pixels, 3)
        rendered = (np.abs(x_mm[window])[:, None] * columns).sum(0) / columns.sum(0)
        predicted = (expected_x[:, None] * weights).sum(0) / weights.sum(0)
        rendered_lateral, predicted_lateral = rendered[2] - rendered[0], predicted[2] - predicted[0]
        assert abs(predicted_lateral) > 5 * pitch_mm / 20  # large enough to measure
        assert rendered_lateral == pytest.approx(predicted_lateral, rel=0.10), (angle, rendered, predicted)


def test_sobol_wavelength_is_dimension_5_of_the_joe_kuo_sequence():
    """The unscrambled wavelength points are SciPy's sixth Sobol' dimension (the
    same direction-number file; SciPy's points come in Gray-code order)."""
    from scipy.stats import qmc

    spp = 256
    film, lens, wavelength = np.zeros((spp, 2), np.float32), np.zeros((spp, 2), np.float32), np.zeros(spp, np.float32)
    _native.diagnostics.pixel_samples(_native.diagnostics.SAMPLER_SOBOL_UNSCRAMBLED, 0, 0, film, lens,
                                      wavelength=wavelength)
    scipy_points = qmc.Sobol(d=6, scramble=False).random(spp)
    gray = np.arange(spp) ^ (np.arange(spp) >> 1)
    assert np.allclose(wavelength[gray], scipy_points[:, 5], atol=2 ** -24)
