"""The lens system's spectral trace in lockstep: a batch of samples, each lane
through the glass at its own wavelength, gives the scalar per-wavelength
trace's rays, on every batch kernel this CPU runs: to the last bit in double
precision, to float rounding in single (the render's)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from lenscompare._native import diagnostics
from lenscompare.cameras import camera_for
from lenscompare.render_spectral import lens_indices
from lenscompare.scene import load_scene

from lens_batch_check import assert_batch_matches_scalar

LENSES = Path(__file__).parent / "data" / "lenses"
SCENES = Path(__file__).parent.parent / "reference_scenes"
KERNELS = diagnostics.lens_trace_kernels()
PRECISIONS = ["double", "single"]  # the reference's and the render's (lens_batch_check)
N_SAMPLES = 8003  # not a whole number of batches: the last one has idle lanes


def _lens_camera(tmp_path, lens: Path):
    text = (SCENES / "showcase.toml").read_text().replace(
        'model = "thin"', f'model = "lens"\nlens = "{lens}"').replace("focal_length_mm = 50.0\n", "") \
        .replace("f_number = 2.8\n", "").replace("resolution = [360, 240]", "resolution = [72, 48]")
    path = tmp_path / "s.toml"
    path.write_text(text)
    camera = camera_for(load_scene(path), "lens")
    return camera.native(), camera.prescription


def _samples(seed: int):
    rng = np.random.default_rng(seed)
    raster = (rng.random((N_SAMPLES, 2)) * [72, 48]).astype(np.float32)
    lens = rng.random((N_SAMPLES, 2)).astype(np.float32)
    # Hero wavelengths 100 nm apart, and a few at and past the table's ends (clamped)
    hero = rng.uniform(380.0, 780.0, N_SAMPLES)
    nm = (380.0 + (hero[:, None] - 380.0 + 100.0 * np.arange(4)) % 400.0).astype(np.float32)
    nm[:8] = [[380.0, 780.0, 379.2, 791.0]] * 8
    return raster, lens, nm


def _rays(camera, raster, lens, nm, *, batched: bool):
    n = 4 * len(raster)
    out = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n, np.float32)
    diagnostics.generate_lens_rays_at(camera, raster, lens, nm, batched, *out)
    return out


def _assert_batch_matches_scalar(camera, seed: int, precision: str):
    raster, lens, nm = _samples(seed)
    scalar = _rays(camera, raster, lens, nm, batched=False)
    passed = scalar[2] > 0
    assert np.isfinite(scalar[0]).all() and passed.mean() > 0.2
    assert_batch_matches_scalar(camera, lambda: _rays(camera, raster, lens, nm, batched=True), scalar,
                                kernels=KERNELS, precision=precision)
    return scalar


@pytest.mark.parametrize("lens", ["dgauss_abbe.dat", "biconvex_bk7.abbe.dat"])
@pytest.mark.parametrize("precision", PRECISIONS)
def test_lockstep_spectral_trace_gives_the_scalar_trace(tmp_path, lens, precision):
    camera, prescription = _lens_camera(tmp_path, LENSES / lens)
    camera.set_dispersion(*lens_indices(prescription))
    origin, direction, _ = _assert_batch_matches_scalar(camera, seed=5, precision=precision)
    # The wavelengths really take different paths: a sample's four rays leave in different directions.
    by_sample = direction.reshape(-1, 4, 3)
    alive = (np.abs(by_sample).sum(axis=2) > 0).all(axis=1)
    assert np.abs(by_sample[alive, 0] - by_sample[alive, 2]).max() > 1e-5


@pytest.mark.parametrize("precision", PRECISIONS)
def test_lockstep_trace_with_total_internal_reflection_per_wavelength(tmp_path, precision):
    # The TIR prism of test_spectral with an Abbe number: some lanes die at some wavelengths only.
    lens = tmp_path / "tir.dat"
    lens.write_text("10 8 1.9 19 20\ninf 0 1 19\n")
    camera, prescription = _lens_camera(tmp_path, lens)
    camera.set_dispersion(*lens_indices(prescription))
    _, _, weight = _assert_batch_matches_scalar(camera, seed=7, precision=precision)
    per_sample = (weight.reshape(-1, 4) > 0).sum(axis=1)
    assert ((per_sample > 0) & (per_sample < 4)).any()


@pytest.mark.parametrize("precision", PRECISIONS)
def test_a_surface_that_refracts_at_some_wavelengths_only(tmp_path, precision):
    """Two cemented glasses whose indices are equal at some nm: there the
    surface does not bend the ray (the scalar trace skips it), elsewhere it
    does, lane by lane within one batch."""
    camera, prescription = _lens_camera(tmp_path, LENSES / "dgauss_abbe.dat")
    n_scene, n_film = lens_indices(prescription)
    cemented = 3  # 1.67 | 1.699
    assert n_scene[0, cemented] != n_film[0, cemented] and n_scene[0, cemented] > 1.0
    equal_rows = np.arange(len(n_film)) % 3 == 0
    n_film[equal_rows, cemented] = n_scene[equal_rows, cemented]
    n_scene[equal_rows, cemented + 1] = n_scene[equal_rows, cemented]
    camera.set_dispersion(np.ascontiguousarray(n_scene), np.ascontiguousarray(n_film))
    _assert_batch_matches_scalar(camera, seed=9, precision=precision)
