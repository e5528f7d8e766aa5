"""Back-tracing a scene ray through the glass (LensSystemCamera::film_points_from,
lens/lens_reverse.h): where on the film the ray a sample sends into the
scene at one wavelength comes from at another. The float trace through the
mirrored lens against the Python double trace toward the film
(lenscompare.lenses.trace.trace_from_scene): the same rays pass and block,
and the film points agree to float rounding; at the tracing wavelength
itself the back trace returns the sample's own film point."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from lenscompare._native import diagnostics
from lenscompare.cameras import camera_for
from lenscompare.lenses.trace import trace_from_scene
from lenscompare.render_spectral import lens_indices
from lenscompare.scene import load_scene

SCENES = Path(__file__).parent.parent / "reference_scenes"
LENSES = Path(__file__).parent / "data" / "lenses"
WIDTH, HEIGHT = 180, 120
N_SAMPLES = 6001  # not a whole number of batches


def _camera(tmp_path, lens: Path):
    text = (SCENES / "showcase.toml").read_text().replace(
        'model = "thin"', f'model = "lens"\nlens = "{lens}"').replace("focal_length_mm = 50.0\n", "") \
        .replace("f_number = 2.8\n", "").replace("resolution = [360, 240]", f"resolution = [{WIDTH}, {HEIGHT}]")
    path = tmp_path / "s.toml"
    path.write_text(text)
    camera = camera_for(load_scene(path), "lens")
    native = camera.native()
    native.set_dispersion(*lens_indices(camera.prescription))
    return camera, native


def _back_traced(native, nm: float, back_nm: float, seed: int = 3):
    rng = np.random.default_rng(seed)
    raster = (rng.random((N_SAMPLES, 2)) * [WIDTH, HEIGHT]).astype(np.float32)
    lens = rng.random((N_SAMPLES, 2)).astype(np.float32)
    origin, direction = np.zeros((N_SAMPLES, 3)), np.zeros((N_SAMPLES, 3))
    film, alive = np.zeros((N_SAMPLES, 2)), np.zeros(N_SAMPLES, bool)
    diagnostics.lens_film_points_from(native, raster, lens, np.full(N_SAMPLES, nm, np.float32),
                                      np.full(N_SAMPLES, back_nm, np.float32), origin, direction, film, alive)
    return raster, origin, direction, film, alive


@pytest.mark.parametrize("lens", ["dgauss_abbe.dat", "biconvex_bk7.abbe.dat"])
def test_back_at_the_same_wavelength_returns_the_samples_film_point(tmp_path, lens):
    camera, native = _camera(tmp_path, LENSES / lens)
    raster, _, direction, film, alive = _back_traced(native, 587.0, 587.0)
    passed = np.abs(direction).sum(axis=1) > 0
    assert passed.mean() > 0.2
    # A ray that passes one way passes the other (bar float ties at a rim: none here).
    assert (alive == passed).all()
    mm_per_px = camera.film.width_mm / WIDTH
    own = np.stack([(0.5 * WIDTH - raster[:, 0].astype(np.float64)) * mm_per_px,
                    (raster[:, 1].astype(np.float64) - 0.5 * HEIGHT) * mm_per_px], axis=1)
    # Measured 2.6e-5 mm (float lanes): a ten-thousandth of a 0.2 mm pixel.
    assert np.abs(film[alive] - own[alive]).max() < 1e-4


@pytest.mark.parametrize("back_nm", [380.0, 486.0, 656.0, 780.0])
def test_back_at_another_wavelength_follows_the_double_trace(tmp_path, back_nm):
    camera, native = _camera(tmp_path, LENSES / "dgauss_abbe.dat")
    _, origin, direction, film, alive = _back_traced(native, 587.0, back_nm)
    passed = np.abs(direction).sum(axis=1) > 0
    # The Python trace toward the film, in double, from 1 mm in front of where each ray left.
    ref = trace_from_scene(camera.prescription.at_wavelength(back_nm), origin[passed] + direction[passed],
                           -direction[passed])
    t = (camera.film_z_mm - ref.origins_mm[:, 2]) / np.where(ref.passed, ref.directions[:, 2], 1.0)
    ref_film = ref.origins_mm[:, :2] + ref.directions[:, :2] * t[:, None]
    both = alive[passed] & ref.passed
    # Rays within float rounding of a rim may go either way; there are a handful at most.
    assert (alive[passed] != ref.passed).sum() <= 3
    assert both.sum() > 1000
    assert np.abs(film[passed][both] - ref_film[both]).max() < 2e-4
    # Dispersion really moves the film point (lateral and longitudinal colour): by more than the tolerance.
    own = _back_traced(native, 587.0, 587.0)[3]
    both_back = alive & (own != 0).any(axis=1)
    assert np.abs(film[both_back] - own[both_back]).max() > 5e-3


def test_blocked_at_the_back_wavelength_only(tmp_path):
    # The TIR prism of test_spectral with an Abbe number: some rays that pass at
    # 587 nm meet total internal reflection on the way back at another wavelength.
    lens = tmp_path / "tir.dat"
    lens.write_text("10 8 1.9 19 20\ninf 0 1 19\n")
    _, native = _camera(tmp_path, lens)
    _, _, direction, film, alive = _back_traced(native, 587.0, 380.0)
    passed = np.abs(direction).sum(axis=1) > 0
    assert np.isfinite(film).all()
    assert (alive <= passed).all()
    # Measured: 1139 of 5882 (glass denser at 380 nm); at 780 nm none.
    assert (passed & ~alive).sum() > 100
    assert (film[~alive] == 0).all()
