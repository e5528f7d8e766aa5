"""The lens system's band rays (native/src/cameras/lens_system_bands.cpp): in a
spectral render through a dispersive lens system each sample's ray carries
every wavelength whose film point stays in its pixel, by a model (film point
and rim clearance linear in the glasses' dispersion between d and 380 nm)
that is checked per camera and held here to the traced wavelengths."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from lenscompare._native import diagnostics
from lenscompare.cameras import camera_for
from lenscompare.render import render
from lenscompare.render_spectral import lens_indices
from lenscompare.scene import load_scene

SCENES = Path(__file__).parent.parent / "reference_scenes"
LENSES = Path(__file__).parent / "data" / "lenses"


def _scene(tmp_path, base: str, *, lens: str = "dgauss_abbe.dat", resolution=(72, 48), f_number=None,
           wide_open=False, camera_key=""):
    lens_keys = f'model = "lens"\nlens = "{LENSES / lens}"\n{camera_key}'
    text = (SCENES / base).read_text().replace('model = "thin"', lens_keys)
    text = text.replace("focal_length_mm = 50.0\n", "")
    text = re.sub(r"resolution = \[\d+, \d+\]", f"resolution = [{resolution[0]}, {resolution[1]}]", text)
    if f_number is not None:
        text = text.replace("f_number = 2.1", f"f_number = {f_number!r}")
    if wide_open:
        text = re.sub(r"^f_number = .*\n", "", text, flags=re.M)
    path = tmp_path / f"{base}_{lens}_{f_number}_{len(camera_key)}.toml"
    path.write_text(text)
    return load_scene(path)


def _band_camera(scene):
    camera = camera_for(scene, "lens")
    native = camera.native()
    native.set_dispersion(*lens_indices(camera.prescription))
    native.set_band_rays(True)
    return native


def test_band_rays_keep_every_channel_of_the_traced_wavelengths(tmp_path):
    """Showcase through the Double Gauss with Abbe numbers, wide open: the channel
    means of the band render against four traced hero wavelengths (unbiased),
    each at 256 spp (the two renders' own noise in the means: about 0.05 %).
    Measured 0.01-0.04 % (showcase 360 x 240, 64 spp); carried at d alone, a
    ray passing in blue but not at d was never drawn and blue read 0.6 % low."""
    scene = _scene(tmp_path, "showcase.toml")
    bands = render(scene, spp=256, spectral=True, progress=False)
    assert bands.metadata["spectral"]["lens_bands"]["used"]
    traced = render(scene, spp=256, spectral=True, sample_wavelengths=True, traced_wavelengths=4, progress=False)
    ratio = bands.pixels.reshape(-1, 3).mean(axis=0) / traced.pixels.reshape(-1, 3).mean(axis=0)
    assert np.all(np.abs(ratio - 1.0) < 0.003), ratio


def test_band_rays_have_no_colour_noise_of_drawn_wavelengths(tmp_path):
    """The same seeds' renders twice: the band render's relative RMSE between
    seeds is below the hero wavelengths' (two traced, the drawn default), as
    the whole spectrum rides on each ray (bench/bench_spectral.py: 0.0268
    against 0.0362 on showcase 180 x 120, RGB 0.0271)."""
    scene = _scene(tmp_path, "showcase.toml")

    def relative_rmse(**kw):
        a, b = (render(scene, spp=16, seed=s, spectral=True, progress=False, **kw).pixels for s in (1, 2))
        return float(np.sqrt(np.mean((a - b) ** 2) / 2.0) / np.mean(a))

    assert relative_rmse() < 0.9 * relative_rmse(sample_wavelengths=True)


def test_the_model_holds_wide_open_and_is_refused_behind_a_pinpoint_stop(tmp_path):
    """check_band_model traces rays back at 400-780 nm against the model: wide
    open the model's passes and film points agree (measured: one way 0.007 %,
    film p99 0.021 px, rays passing only away from d 0.34 %); at f/1000 the
    pupils move apart by more than their size (22 % of the rays pass away from
    d only) and the render draws hero wavelengths instead."""
    wide = _band_camera(_scene(tmp_path, "flat_field.toml"))
    passing, one_way, film_p99_px, rays, elsewhere = wide.check_band_model()
    assert passing > 40000 and one_way / passing < 0.001 and film_p99_px < 0.05 and elsewhere / rays < 0.01
    pinpoint = _scene(tmp_path, "flat_field.toml", f_number=1000.0)
    image = render(pinpoint, spp=4, spectral=True, progress=False)
    info = image.metadata["spectral"]["lens_bands"]
    assert not info["used"] and "passing_only_away_from_d" in info["reason"]
    assert image.metadata["spectral"]["wavelengths_sampled"]


def test_each_samples_bands_tile_its_spectrum_once(tmp_path):
    """lens_band_rays: a sample's rays in order, their bands of the dispersion
    parameter back to back over the part of the spectrum its ray passes (all of
    it, for rays well inside every rim), every ray finite, weights >= 0."""
    native = _band_camera(_scene(tmp_path, "showcase.toml", resolution=(720, 480)))  # fine pixels: many splits
    k = np.asarray(native.band_parameter)
    rng = np.random.default_rng(7)
    n = 32 * 40
    raster = (rng.random((n, 2)) * [720, 480]).astype(np.float32)
    lens = rng.random((n, 2)).astype(np.float32)
    room = 16 * n
    out = (np.zeros(room, np.int32), np.zeros((room, 3)), np.zeros((room, 3)), np.zeros(room), np.zeros(room),
           np.zeros(room, bool), np.zeros(room))
    count = diagnostics.lens_band_rays(native, raster, lens, *out)
    sample, origin, direction, k_lo, k_hi, whole, weight = (a[:count] for a in out)
    assert np.isfinite(origin).all() and np.isfinite(direction).all() and (weight >= 0.0).all()
    assert np.array_equal(np.unique(sample), np.arange(n)) and np.all(np.diff(sample) >= 0)
    split = ~whole
    assert 0.05 < np.mean(np.bincount(sample) > 1) < 0.95  # both kinds are tested
    full = 0
    for s in np.unique(sample[split]):
        rows = np.nonzero(sample == s)[0]
        assert np.allclose(k_lo[rows[1:]], k_hi[rows[:-1]])  # back to back, in k order
        assert k.min() - 1e-12 <= k_lo[rows[0]] and k_hi[rows[-1]] <= k.max() + 1e-12
        full += np.isclose(k_lo[rows[0]], k.min()) and np.isclose(k_hi[rows[-1]], k.max())
    assert full > 0.9 * len(np.unique(sample[split]))


@pytest.mark.parametrize("base, camera_key", [("showcase.toml", "aperture_blades = 5"), ("moving_showcase.toml", "")])
def test_band_rays_through_blades_and_a_moving_camera_keep_the_traced_colour(tmp_path, base, camera_key):
    """A bladed stop (no table: every sample traced back at 380 nm) and a moving
    camera (each ray's origin where the camera is at its sample's time): channel
    means against four traced hero wavelengths (measured within 0.06 %)."""
    scene = _scene(tmp_path, base, camera_key=camera_key)
    bands = render(scene, spp=64, spectral=True, progress=False)
    assert bands.metadata["spectral"]["lens_bands"]["used"] and np.isfinite(bands.pixels).all()
    traced = render(scene, spp=64, spectral=True, sample_wavelengths=True, traced_wavelengths=4, progress=False)
    ratio = bands.pixels.reshape(-1, 3).mean(axis=0) / traced.pixels.reshape(-1, 3).mean(axis=0)
    assert np.all(np.abs(ratio - 1.0) < 0.004), ratio


def test_band_renders_do_not_depend_on_the_thread_count_with_split_samples_pooled(tmp_path):
    # Fine pixels: a third of the samples split, their rays pooled across batches (render_tile_bands.h).
    scene = _scene(tmp_path, "showcase.toml", resolution=(240, 160))
    one = render(scene, spp=4, spectral=True, threads=1, progress=False)
    two = render(scene, spp=4, spectral=True, threads=2, progress=False)
    assert np.array_equal(one.pixels, two.pixels)


@pytest.mark.parametrize("model", ["lens", "thin"])
def test_roulette_on_split_samples_keeps_the_image_and_adds_little_noise(tmp_path, model):
    """Russian roulette on a split sample's ray a pixel away (BandRoulette in
    native/src/spectral_bands.h), against every split sample traced, the same
    seed (the same samples; only the split samples' estimate differs), for the
    lens system and the thin lens derived from it: the channel means within
    0.05 % (unbiased; measured 0.001-0.008 %), and the per-pixel RMS of the
    difference under 0.4 of one render's own noise (the variance it adds:
    measured 0.17 and 0.27, about 3 and 7 %). With the two rays' whole-
    spectrum parts swapped (an estimator biased at edges and weighed by 1 / q)
    the lens system's difference was 2.2 times the noise and its means 0.11 %
    apart."""
    scene = _scene(tmp_path, "showcase.toml", resolution=(120, 80))

    def pixels(seed, roulette):
        image = render(scene, model=model, spp=64, seed=seed, spectral=True, progress=False,
                       band_roulette=roulette)
        assert image.metadata["spectral"]["band_roulette_gain"] == (0.75 if roulette else None)
        return image.pixels

    on, off, other_seed = pixels(1, True), pixels(1, False), pixels(2, False)
    ratio = on.reshape(-1, 3).mean(axis=0) / off.reshape(-1, 3).mean(axis=0)
    assert np.all(np.abs(ratio - 1.0) < 5e-4), ratio
    noise = np.sqrt(np.mean((off - other_seed) ** 2) / 2.0)
    assert np.sqrt(np.mean((on - off) ** 2)) < 0.4 * noise


@pytest.mark.parametrize("lens, used", [("dgauss_abbe.dat", True), ("cooke_triplet.abbe.dat", True),
                                        ("sasian_triplet.glass.dat", False), ("telescope_triplet.glass.dat", False)])
def test_abbe_glass_carries_bands_and_catalogue_glass_draws_wavelengths(tmp_path, lens, used):
    """Film point error p99 of the linear model in k over 400-780 nm, checked
    per camera (check_band_model), showcase 360 x 240 wide open: with Abbe
    numbers every index is linear in 1 / λ² and the lens a one-parameter
    family (measured 0.042 and 0.041 px); catalogue glasses' partial
    dispersions differ, so no one k fits all (0.40 and 0.83 px) and those
    renders draw hero wavelengths."""
    scene = _scene(tmp_path, "showcase.toml", lens=lens, resolution=(360, 240), wide_open=True)
    native = _band_camera(scene)
    passing, one_way, film_p99_px, _, _ = native.check_band_model()
    assert (film_p99_px < 0.1) == used and one_way / passing < 0.01
    image = render(scene, spp=1, spectral=True, progress=False)
    assert image.metadata["spectral"]["lens_bands"]["used"] == used


@pytest.mark.parametrize("lens", ["dgauss_abbe.dat", "cooke_triplet.abbe.dat", "biconvex_bk7.abbe.dat"])
def test_the_band_table_answers_as_the_trace_back_at_380_nm(tmp_path, lens):
    """The band table (lens_band_table.h, 16 x 32 cells a ring) against the
    back-trace it stands in for, showcase 360 x 240 wide open, 16,000 random
    samples: the film point at the spectrum's far end it implies (shift x
    (k(380 nm) - k_d)) within 0.002 mm at the 99th percentile (measured
    0.0005, 0.0003 and 0.0016 mm, a pixel being 0.1 mm) and 5 % of the shift
    itself (1.7, 4.2 and 0.5 %), and the clearance there within 0.01 of the
    rim (measured 0.0023, 0.0056, 0.00002)."""
    scene = _scene(tmp_path, "showcase.toml", lens=lens, resolution=(360, 240), wide_open=True)
    native = _band_camera(scene)
    k = np.asarray(native.band_parameter)
    k_d = np.interp(587.56, 380 + np.arange(len(k)), k)
    dk = k[0] - k_d
    rng = np.random.default_rng(5)
    n = 16_000
    raster = (rng.random((n, 2)) * (360, 240)).astype(np.float32)
    lens_sample = rng.random((n, 2)).astype(np.float32)
    found = {}
    for from_table in (True, False):
        values, known = np.zeros((n, 3)), np.zeros(n, bool)
        diagnostics.lens_band_shifts(native, raster, lens_sample, from_table, values, known)
        found[from_table] = values, known
    (table, table_known), (traced, traced_known) = found[True], found[False]
    assert table_known.mean() > 0.99 and traced_known.mean() > 0.99
    both = table_known & traced_known
    film_error_mm = np.hypot(*(table[both, :2] - traced[both, :2]).T) * abs(dk)
    shift_mm = np.hypot(*traced[both, :2].T) * abs(dk)
    assert np.percentile(film_error_mm, 99) < 0.002
    assert np.percentile(film_error_mm / np.maximum(shift_mm, 1e-9), 99) < 0.05
    assert np.percentile(np.abs(table[both, 2] - traced[both, 2]) * abs(dk), 99) < 0.01
