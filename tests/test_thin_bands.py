"""Spectral renders through a dispersive thin lens whose rays carry bands of
wavelengths (session 29; native/src/render_tile_bands.h): each wavelength's
ray is its own camera's, the bands of a sample cover the spectrum once, the
wavelengths of a band are those whose plane of focus lies in it, and the
render is the drawn-wavelength render's expectation without its colour noise."""

from pathlib import Path

import numpy as np
import pytest

from lenscompare._native import diagnostics
from lenscompare.cameras import camera_for
from lenscompare.render import render
from lenscompare.render_spectral import inverse_focus_per_m
from lenscompare.scene import load_scene
from lenscompare.spectral import basis_table, film_table, wavelengths_nm

ROOT = Path(__file__).resolve().parent.parent
DISPERSIVE_LENS = ROOT / "tests" / "data" / "lenses" / "dgauss_abbe.dat"


def _scene(name="showcase", resolution=(72, 48), **camera):
    scene = load_scene(ROOT / "reference_scenes" / f"{name}.toml")
    return scene.with_camera(resolution=resolution, lens=str(DISPERSIVE_LENS), focal_length_mm=None, **camera)


def _camera(scene, *, disk_mapping="concentric", table=None):
    camera = camera_for(scene, "thin")
    native = camera.native(disk_mapping=disk_mapping)
    if table is None:
        table = inverse_focus_per_m(scene.camera.lens, film_distance_mm=camera.film_distance_mm,
                                    focal_length_mm=camera.focal_length_mm)
    native.set_dispersion(np.ascontiguousarray(table, dtype=np.float64))
    return native, table


def _band_rays(camera, raster, lens):
    room = 8 * len(raster)
    out = (np.zeros(room, np.int32), np.zeros((room, 3)), np.zeros((room, 3)), np.zeros(room), np.zeros(room),
           np.zeros(room, bool))
    count = diagnostics.thin_band_rays(camera, raster, lens, *out)
    return tuple(a[:count] for a in out)


@pytest.mark.parametrize("disk_mapping", ["concentric", "polar"])
def test_each_wavelength_rides_its_own_cameras_ray(disk_mapping):
    """For any wavelength, the ray whose band holds its plane of focus is the
    ray its own camera traces from its film point wrapped into the pixel
    (generate_rays_sharing's, the one-sample reference in double)."""
    scene = _scene(resolution=(720, 480))  # fine pixels: many samples straddle an edge
    camera, table = _camera(scene, disk_mapping=disk_mapping)
    rng = np.random.default_rng(29)
    count = 32 * 20 + 5
    raster = (rng.random((count, 2)) * [720, 480]).astype(np.float32)
    lens = rng.random((count, 2)).astype(np.float32)
    sample, origin, direction, k_lo, k_hi, whole = _band_rays(camera, raster, lens)
    assert 0.2 < 1.0 - whole.mean() < 0.9  # both kinds are tested
    # The hero at the d line: its plane of focus is the bands' reference (DispersionRuns::reference).
    nm = wavelengths_nm()
    hero = 587.56
    others = rng.uniform(380.0, 780.0, (count, 3))
    quads = np.column_stack([np.full(count, hero), others]).astype(np.float32)
    reference = np.zeros((4 * count, 3)), np.zeros((4 * count, 3)), np.zeros(4 * count, bool)
    diagnostics.generate_thin_rays_sharing(camera, raster, lens, quads, False, *reference)
    for i in range(count):
        for k in (1, 2, 3):
            k_of = np.interp(float(quads[i, k]), nm, table)
            rays = np.flatnonzero((sample == i) & (k_lo <= k_of) & (k_of < k_hi))
            assert len(rays) == 1, (i, k)
            assert np.abs(origin[rays[0]] - reference[0][4 * i + k]).max() < 2e-6
            assert np.abs(direction[rays[0]] - reference[1][4 * i + k]).max() < 2e-6


def test_a_samples_bands_cover_the_spectrum_once():
    scene = _scene(resolution=(1440, 960))
    camera, table = _camera(scene)
    rng = np.random.default_rng(7)
    count = 32 * 10
    raster = (rng.random((count, 2)) * [1440, 960]).astype(np.float32)
    lens = rng.random((count, 2)).astype(np.float32)
    sample, _, _, k_lo, k_hi, whole = _band_rays(camera, raster, lens)
    assert np.bincount(sample, minlength=count).max() >= 3  # both edges crossed somewhere
    for i in range(count):
        lo, hi = k_lo[sample == i], k_hi[sample == i]
        assert lo[0] == table.min() and hi[-1] == table.max()
        np.testing.assert_array_equal(lo[1:], hi[:-1])  # contiguous, in order
        assert np.all(hi > lo)
        assert whole[sample == i].all() == (len(lo) == 1)


def test_a_band_of_planes_of_focus_is_the_wavelengths_focused_in_it():
    """A focus that turns back (an achromat's parabola) gives a band two
    intervals of wavelength; each is where the linear-between-nm table lies in
    the band, as a dense evaluation of that table finds."""
    scene = _scene()
    nm = wavelengths_nm()
    table = 0.3 + 1e-6 * (nm - 560.0) ** 2  # lowest at 560 nm
    camera, _ = _camera(scene, table=table)
    assert camera.carries_bands()
    dense = np.linspace(380.0, 780.0, 400001)
    k_dense = np.interp(dense, nm, table)
    for k_lo, k_hi in ((0.30, 0.31), (0.301, 0.305), (0.3005, 0.4), (0.2, 0.3001)):
        band = diagnostics.dispersion_band(camera, k_lo, k_hi)
        inside = (k_dense >= k_lo) & (k_dense < k_hi)
        found = np.zeros_like(inside)
        for start, end in band:
            found |= (dense >= start) & (dense <= end)
        assert np.mean(found != inside) < 1e-4, (k_lo, k_hi, band)
    # A focus that turns back and forth many times draws wavelengths instead.
    zigzag, _ = _camera(scene, table=0.3 + 1e-3 * np.sin(nm / 10.0))
    assert not zigzag.carries_bands()


def test_the_band_render_is_the_drawn_renders_expectation():
    """Channel means of showcase through the dispersive thin lens: the band
    render against hero wavelengths drawn (both unbiased), 64 spp, 72x48:
    within 0.3 % (measured 0.02 %); and its relative RMSE lower."""
    scene = _scene()
    bands = [render(scene, model="thin", spp=64, seed=s, spectral=True, progress=False) for s in (1, 2)]
    drawn = [render(scene, model="thin", spp=64, seed=s, spectral=True, sample_wavelengths=True,
                    progress=False) for s in (1, 2)]
    assert bands[0].metadata["spectral"]["wavelengths_sampled"] is False
    assert drawn[0].metadata["spectral"]["wavelengths_sampled"] is True

    def mean(images):
        return np.mean([im.pixels.reshape(-1, 3).mean(axis=0) for im in images], axis=0)

    def rmse(images):
        a, b = (im.pixels.astype(np.float64) for im in images)
        return np.sqrt(np.mean((a - b) ** 2) / 2.0) / np.mean(0.5 * (a + b))

    assert np.all(np.abs(mean(bands) / mean(drawn) - 1.0) < 0.003), (mean(bands), mean(drawn))
    assert rmse(bands) < rmse(drawn)


def test_a_flat_field_through_the_dispersive_thin_lens_has_no_colour_noise():
    """Equal-energy white everywhere: every sample's bands add up to the
    whole spectrum, so every pixel reads the same white (drawn wavelengths:
    colour noise of about 1e-2)."""
    scene = _scene("flat_field", resolution=(48, 32))
    bands = render(scene, model="thin", spp=4, spectral=True, progress=False).pixels
    drawn = render(scene, model="thin", spp=4, spectral=True, sample_wavelengths=True, progress=False).pixels
    assert bands.std(axis=(0, 1)).max() < 1e-5 * bands.mean()
    assert drawn.std(axis=(0, 1)).max() > 1e-3 * drawn.mean()


def test_the_thick_lens_carries_the_thin_lenses_bands():
    thin = render(_scene(), model="thin", spp=4, spectral=True, progress=False)
    thick = render(_scene(), model="thick", spp=4, spectral=True, progress=False)
    assert thick.metadata["spectral"]["secondaries"] == thin.metadata["spectral"]["secondaries"]
    assert thin.metadata["spectral"]["secondaries"].startswith("none: a ray per stretch")


def test_a_moving_camera_keeps_its_band_rays():
    """A camera moving during the shutter (a translation moves every
    wavelength's ray alike): still bands, no wavelength drawn, the channel
    means of the drawn render within 0.3 %, and the same image for 1 and 2
    threads. A camera that moves its whole width in the shutter blurs: the
    image differs from the still one's."""
    moving = _scene(velocity=(0.5, 0.0, 0.0)).with_render(shutter_s=(0.0, 0.04))
    bands = [render(moving, model="thin", spp=64, seed=s, spectral=True, progress=False, threads=t)
             for s, t in ((1, 1), (2, 2))]
    drawn = [render(moving, model="thin", spp=64, seed=s, spectral=True, sample_wavelengths=True,
                    progress=False) for s in (1, 2)]
    assert bands[0].metadata["spectral"]["secondaries"].startswith("none: a ray per stretch")
    assert bands[0].metadata["spectral"]["wavelengths_sampled"] is False
    means = [np.mean([im.pixels.reshape(-1, 3).mean(axis=0) for im in images], axis=0) for images in (bands, drawn)]
    assert np.all(np.abs(means[0] / means[1] - 1.0) < 0.003), means
    again = render(moving, model="thin", spp=64, seed=2, spectral=True, progress=False, threads=1)
    assert again.pixels.tobytes() == bands[1].pixels.tobytes()
    still = render(_scene(), model="thin", spp=64, seed=2, spectral=True, progress=False)
    assert np.abs(still.pixels - bands[1].pixels).mean() > 0.01 * still.pixels.mean()


def _dense_band_map(table, k_lo, k_hi, intensity=None, samples=400_001):
    """map[k][c] = ∫ film_k B_c [I] over {λ: k_lo <= k(λ) < k_hi}, every table read linearly, by a dense sum."""
    nm = wavelengths_nm()
    dense = np.linspace(nm[0], nm[-1], samples)
    step = dense[1] - dense[0]
    k_dense = np.interp(dense, nm, table)
    inside = (k_dense >= k_lo) & (k_dense < k_hi)
    basis = np.stack([np.interp(dense, nm, basis_table()[:, c]) for c in range(3)], axis=1)
    film = np.stack([np.interp(dense, nm, film_table()[:, k]) for k in range(3)], axis=1)
    weight = inside * step
    if intensity is not None:
        weight = weight * (basis @ np.asarray(intensity, dtype=np.float64))
    return np.einsum("n,nk,nc->kc", weight, film, basis)


@pytest.mark.parametrize("shape", ["lens", "falling", "three_runs"])
def test_a_bands_film_reading_is_the_integral_over_its_wavelengths(shape):
    """FocusBandIntegrals (spectral_bands.h), the map a ray of a band of
    planes of focus reads, against a dense sum over the wavelengths whose
    plane lies in the band: the lens's table (rising), a falling one and
    one that turns twice; of the basis colours and lit by a light; agree
    within 3e-5 of the whole spectrum's map (measured 1e-6 to 4e-6 on the
    lens's)."""
    scene = _scene()
    nm = wavelengths_nm()
    if shape == "lens":
        _, table = _camera(scene)
    elif shape == "falling":
        table = 0.31 - 1e-6 * (nm - 380.0) ** 2
    else:
        table = 0.3 + 1e-3 * np.sin((nm - 380.0) / 400.0 * 2.5 * np.pi)
    table = np.asarray(table, dtype=np.float64)
    light = (0.9, 0.5, 0.2)
    lo, hi = float(table.min()), float(table.max())
    span = hi - lo
    bands = [(lo, hi), (lo, lo + 0.3 * span), (lo + 0.3 * span, hi), (lo + 0.1 * span, lo + 0.12 * span),
             (lo + 0.55 * span, lo + 0.9 * span)]
    for index, intensity in ((0, None), (1, light)):
        whole = _dense_band_map(table, lo, np.inf, intensity)
        for k_lo, k_hi in bands:
            k_top = np.inf if k_hi == hi else k_hi  # the last band holds the highest plane too
            expected = _dense_band_map(table, k_lo, k_top, intensity)
            got = np.array(diagnostics.focus_band_map(basis_table(), film_table(), [light], table, index, k_lo, k_hi))
            assert np.abs(got - expected).max() < 3e-5 * np.abs(whole).max(), (shape, index, k_lo, k_hi)
