"""Spectral renders through a camera that does not disperse integrate the
wavelengths exactly instead of drawing them (native/src/spectral.h,
integrate_still): the film's reading of every colour and of every lit
reflectance is a fixed linear map of the file's RGB, taken once.

The expected values here come from numpy integrals of lenscompare.spectral's
own tables (colour-science's Mallett-Yuksel basis and CIE 1931 observer),
computed independently of the native Simpson sums, and from the sampled
hero-wavelength estimator that the integral must be the expectation of."""

from __future__ import annotations

import numpy as np
import pytest

from helpers import MINIMAL_SCENE
from lenscompare.render import render
from lenscompare.scene import load_scene
from lenscompare.spectral import LINE_WIDTH_NM, basis_table, film_table, line_radiance, wavelengths_nm

from test_spectral import SCENES

def _wall_scene(tmp_path, material: str, lights: str = ""):
    """A pinhole facing a wall of the given material that fills the view, on black."""
    text = MINIMAL_SCENE.split("[materials.glow]")[0].replace('model = "thin"', 'model = "pinhole"') + f"""
[background]
color = [0.0, 0.0, 0.0]

[materials.wall]
{material}

[[objects]]
type = "rectangle"
corner = [-50.0, -50.0, 2.0]
edge1 = [100.0, 0.0, 0.0]
edge2 = [0.0, 100.0, 0.0]
material = "wall"
{lights}"""
    path = tmp_path / "s.toml"
    path.write_text(text)
    return load_scene(path)


def _fine(table: np.ndarray, per_nm: int = 20) -> np.ndarray:
    """The table linearly interpolated at per_nm points per nm (as the native code reads it)."""
    fine_nm = np.linspace(wavelengths_nm()[0], wavelengths_nm()[-1], 400 * per_nm + 1)
    return fine_nm, np.stack([np.interp(fine_nm, wavelengths_nm(), table[:, c]) for c in range(3)], axis=1)


def _film_reading(spectrum_nm: np.ndarray, spectrum: np.ndarray) -> np.ndarray:
    """∫ film(λ) spectrum(λ) dλ, trapezoid on the fine grid."""
    _, film = _fine(film_table())
    return np.trapezoid(film * spectrum[:, None], spectrum_nm, axis=0)


def _spectrum(rgb, fine_basis: np.ndarray) -> np.ndarray:
    return fine_basis @ np.asarray(rgb, dtype=float)


def test_a_white_flat_field_reads_one_in_every_pixel_with_no_colour_noise():
    scene = load_scene(SCENES / "flat_field.toml").with_camera(model="pinhole", resolution=(36, 24))
    integrated = render(scene, spp=4, spectral=True, progress=False)
    assert integrated.metadata["spectral"]["wavelengths_sampled"] is False
    assert np.allclose(integrated.pixels, 1.0, atol=2e-5)
    # Drawn wavelengths give the same mean with colour noise around it
    sampled = render(scene, spp=4, spectral=True, sample_wavelengths=True, progress=False)
    assert sampled.metadata["spectral"]["wavelengths_sampled"] is True
    assert sampled.pixels.std() > 100 * integrated.pixels.std()


def test_a_lit_reflectance_reads_the_product_of_its_spectra_not_of_its_rgb(tmp_path):
    """Red albedo under a green light: RGB multiplies (0.9, 0.05, 0.05) by
    (0.05, 0.9, 0.05) channel by channel; the spectra overlap, so the film
    sees more. The integral of film x R(λ) x I(λ) computed here with numpy
    is what every pixel must read."""
    albedo, light = (0.9, 0.05, 0.05), (0.05, 0.9, 0.05)
    # Lit from the camera by one light without falloff (the contract's default):
    # every pixel is albedo x light x its cosine.
    scene = _wall_scene(tmp_path, f'type = "diffuse"\ncolor = {list(albedo)}',
                        f'[[lights]]\ntype = "point"\nposition = [0.0, 0.0, 0.0]\ncolor = {list(light)}')
    spectral = render(scene, spp=2, spectral=True, progress=False).pixels.reshape(-1, 3)
    rgb = render(scene, spp=2, progress=False).pixels.reshape(-1, 3)
    fine_nm, basis = _fine(basis_table())
    expected = _film_reading(fine_nm, _spectrum(albedo, basis) * _spectrum(light, basis))
    # The geometry (the cosine at each pixel) is the same for both: compare per unit of it.
    geometry = rgb / np.multiply(albedo, light)
    assert np.allclose(geometry, geometry[:, :1], rtol=1e-5)
    assert np.allclose(spectral / geometry, expected, rtol=1e-4), (spectral[0] / geometry[0], expected)
    assert np.all(np.abs(spectral[0] / rgb[0] - 1.0) > 0.1)  # a difference RGB cannot show


def test_a_monochromatic_emitter_reads_its_line_through_the_film(tmp_path):
    nm = 486.13
    scene = _wall_scene(tmp_path, f'type = "emissive"\ncolor = [0.2, 0.5, 1.0]\nwavelength_nm = {nm}')
    pixels = render(scene, spp=2, spectral=True, progress=False).pixels.reshape(-1, 3)
    band_nm = np.linspace(nm - 0.5 * LINE_WIDTH_NM, nm + 0.5 * LINE_WIDTH_NM, 2001)
    film = np.stack([np.interp(band_nm, wavelengths_nm(), film_table()[:, c]) for c in range(3)], axis=1)
    expected = np.trapezoid(film, band_nm, axis=0) * line_radiance((0.2, 0.5, 1.0), nm)
    assert np.allclose(pixels, expected, rtol=1e-4), (pixels[0], expected)


@pytest.mark.parametrize("model", ["thin", "pinhole"])
def test_the_integral_is_the_expectation_of_drawn_wavelengths(model):
    """Showcase (two coloured lights, checker, emitters): the channel means of
    the integrated render and of 256 drawn wavelengths per pixel agree within
    0.1 % (measured: within 1e-5 at 180x120, 1024 spp), and the integrated
    render is no noisier than the RGB one, by its difference to a second seed."""
    scene = load_scene(SCENES / "showcase.toml").with_camera(model=model, resolution=(90, 60))
    integrated = render(scene, spp=16, seed=1, spectral=True, progress=False).pixels
    sampled = render(scene, spp=256, seed=2, spectral=True, sample_wavelengths=True, progress=False).pixels
    means = [image.reshape(-1, 3).mean(axis=0) for image in (integrated, sampled)]
    assert np.all(np.abs(means[0] / means[1] - 1.0) < 1e-3), means
    other_seed = render(scene, spp=16, seed=3, spectral=True, progress=False).pixels
    rgb = [render(scene, spp=16, seed=seed, progress=False).pixels for seed in (1, 3)]
    spectral_noise = np.sqrt(np.mean((integrated - other_seed) ** 2))
    rgb_noise = np.sqrt(np.mean((rgb[0] - rgb[1]) ** 2))
    assert spectral_noise < 1.05 * rgb_noise, (spectral_noise, rgb_noise)


def test_integrated_renders_do_not_depend_on_the_thread_count_and_hold_no_nan():
    scene = load_scene(SCENES / "showcase.toml").with_camera(resolution=(64, 48))
    one, two = (render(scene, spp=4, spectral=True, threads=t, progress=False).pixels for t in (1, 2))
    assert np.array_equal(one, two)
    assert np.all(np.isfinite(one))
