"""The lens system's per-tile pencils (native lens_pencil.h): measured bounds of
the rays through each film tile, checked against every traced batch, so that a
tile skips the own spheres and quads none of its rays can meet.

What must hold: the image is the same bit for bit with the pencils, without
them, and with pencils so tight that nearly every batch leaves its tile's (the
render's fallback to testing every primitive); the bounds hold the rays of
the shipped lenses (so the cull is not a dead letter).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from lenscompare import _native
from lenscompare._native import diagnostics
from lenscompare.cameras import camera_for
from lenscompare.cameras.lens_ray_table import use_ray_table
from lenscompare.native_scene import build_native_scene
from lenscompare.render import SAMPLER_CODES
from lenscompare.render_spectral import make_spectral
from lenscompare.scene import load_scene

ROOT = Path(__file__).resolve().parent.parent
TEST_LENSES = ROOT / "tests" / "data" / "lenses"
# A scene of boxes, rectangles and spheres (the own quads, their faces and spheres)
PEERS = ROOT / "bench" / "scenes" / "peers_lit.toml"
SHIPPED = ["dgauss.50mm", "wide.22mm", "fisheye.10mm", "telephoto.250mm"]
HARD = ["cemented_zero_layer.dat", "planoconvex_flat_front.dat", "biconvex_stop_front.dat"]


def lens_camera_scene(lens: str, *, resolution=(96, 64)):
    scene = load_scene(PEERS).with_camera(lens=lens, f_number=None, resolution=resolution, focal_length_mm=None)
    return scene, camera_for(scene, "lens").native()


def render_native(scene, camera, *, spp=4, seed=5, threads=2, native_scene=None):
    width, height = scene.camera.resolution
    native_scene = build_native_scene(scene) if native_scene is None else native_scene
    pixels = np.zeros((height, width, 3), dtype=np.float32)
    variance = np.zeros((height, width), dtype=np.float32)
    _native.render_rows(native_scene, camera, spp, SAMPLER_CODES["jittered"], seed, threads, 0, height,
                        pixels, variance)
    return pixels


@pytest.mark.parametrize("lens", SHIPPED + [str(TEST_LENSES / name) for name in HARD])
def test_image_same_with_and_without_pencils(lens):
    scene, camera = lens_camera_scene(lens)
    measured = render_native(scene, camera)
    diagnostics.set_lens_pencils(camera, "none")
    without = render_native(scene, camera)
    diagnostics.set_lens_pencils(camera, "collapsed")
    collapsed = render_native(scene, camera)
    assert np.isfinite(measured).all()
    assert measured.mean() > 0.0
    np.testing.assert_array_equal(measured, without)
    np.testing.assert_array_equal(collapsed, without)


@pytest.mark.parametrize("traced", [1, 2, 4])
def test_spectral_image_same_with_and_without_pencils(traced):
    """Through a dispersive lens each traced wavelength has a ray of its own, off
    the d-line rays the pencils were measured with: every one is checked."""
    scene = load_scene(PEERS).with_camera(lens=str(TEST_LENSES / "dgauss_abbe.dat"), f_number=None,
                                          resolution=(96, 64), focal_length_mm=None)
    camera = camera_for(scene, "lens")
    native_scene, native_camera = build_native_scene(scene), camera.native()
    assert make_spectral(native_scene, native_camera, scene, camera, traced_wavelengths=traced)["camera_disperses"]
    images = {}
    for mode in ("measured", "none", "collapsed"):
        diagnostics.set_lens_pencils(native_camera, mode)
        images[mode] = render_native(scene, native_camera, native_scene=native_scene)
    assert np.isfinite(images["measured"]).all()
    assert images["measured"].mean() > 0.0
    np.testing.assert_array_equal(images["measured"], images["none"])
    np.testing.assert_array_equal(images["collapsed"], images["none"])


def tile_samples(x0, y0, size_px, n, rng):
    raster = (np.array([x0, y0]) + rng.random((n, 2)) * size_px).astype(np.float32)
    return raster, rng.random((n, 2)).astype(np.float32)


def batches_within_pencils(camera, *, seed, tiles_without=False):
    """(batches within their tile's pencil, batches) for 1024 random samples in each 16-pixel
    tile of a 240 x 160 film; tiles_without: tiles with no pencil (skipped) are expected."""
    rng = np.random.default_rng(seed)
    within = batches = 0
    for y0 in range(0, 160, 16):
        for x0 in range(0, 240, 16):
            if diagnostics.lens_pencil(camera, x0, y0, x0 + 16, y0 + 16) is None:
                assert tiles_without
                continue
            raster, u = tile_samples(x0, y0, 16, 1024, rng)
            w, b = diagnostics.lens_rays_within_pencil(camera, x0, y0, x0 + 16, y0 + 16, raster, u)
            within, batches = within + w, batches + b
    return within, batches


@pytest.mark.parametrize("lens, least_fraction", [("dgauss.50mm", 1.0), ("wide.22mm", 1.0),
                                                  ("telephoto.250mm", 1.0), ("fisheye.10mm", 0.9)])
def test_pencils_hold_the_rays(lens, least_fraction):
    """Batches of random samples per 16-pixel tile stay within its pencil (all
    of them but the fisheye's, whose rays bend most; its corners outside the
    image circle have none)."""
    scene, camera = lens_camera_scene(lens, resolution=(240, 160))
    within, batches = batches_within_pencils(camera, seed=2, tiles_without=lens == "fisheye.10mm")
    assert batches > 0
    assert within / batches >= least_fraction


@pytest.mark.parametrize("lens", ["dgauss.50mm", "wide.22mm", "telephoto.250mm"])
def test_pencils_hold_the_ray_tables_rays(lens):
    """With its rays from the table (lens_rays = "table") every batch stays within its tile's pencil
    too: the table's interpolated origins may lie past the first surface's cap (its nodes are traced
    without the rims), so the pencils' plane lies behind them; in front of them, the live rays near
    the rim failed the check and a tenth of showcase's tiles tested every primitive."""
    scene = load_scene(PEERS).with_camera(lens=lens, f_number=None, resolution=(240, 160), focal_length_mm=None)
    python_camera = camera_for(scene, "lens")
    camera = python_camera.native()
    assert use_ray_table(python_camera, camera)["from"] == "table" and camera.uses_ray_table
    within, batches = batches_within_pencils(camera, seed=3)
    assert batches == 150 * 32 and within == batches


@pytest.mark.parametrize("lens", ["dgauss_abbe.dat", "cooke_triplet.abbe.dat"])
def test_band_pencils_hold_the_band_rays(lens):
    """A spectral render through a dispersive lens system sends band rays
    (traced at d with the rims stopping none, each kept where some band of
    the spectrum passes, and split rays from a pixel away): every batch of
    every 16-pixel tile stays within its pencil. (Checked against the d
    line's pencils, showcase's at 180x120 through the Double Gauss held 2542
    of 3072 batches and 30 of 96 tiles throughout; the others tested every
    primitive from their first batch outside on: session 51.)"""
    scene = load_scene(PEERS).with_camera(lens=str(TEST_LENSES / lens), f_number=None, resolution=(240, 160),
                                          focal_length_mm=None)
    camera = camera_for(scene, "lens")
    native_camera = camera.native()
    info = make_spectral(build_native_scene(scene), native_camera, scene, camera)
    assert info["lens_bands"]["used"]
    within, batches = batches_within_pencils(native_camera, seed=2)
    assert batches == 150 * 32
    assert within == batches


def test_collapsed_pencils_are_left():
    """The fallback test above is not vacuous: collapsed pencils hold almost no batch."""
    scene, camera = lens_camera_scene("dgauss.50mm", resolution=(240, 160))
    diagnostics.set_lens_pencils(camera, "collapsed")
    raster, u = tile_samples(112, 80, 16, 1024, np.random.default_rng(3))
    within, batches = diagnostics.lens_rays_within_pencil(camera, 112, 80, 128, 96, raster, u)
    assert within == 0 and batches == 32


def test_centre_pencil_is_tight():
    """The centre tile's screen range (focused rays, a 16-pixel tile) is a few
    tile widths at most, and k puts the rays' crossing near the 2.5 m focus."""
    scene, camera = lens_camera_scene("dgauss.50mm", resolution=(240, 160))
    screen_lo, screen_hi, radius_m, inverse_focus_per_m = diagnostics.lens_pencil(camera, 112, 72, 128, 88)
    tile_width = 16 * (36.0 / 240) / 50.0  # screen units (tan) of 16 pixels
    assert 0.0 < screen_hi[0] - screen_lo[0] < 4 * tile_width
    assert 0.0 < screen_hi[1] - screen_lo[1] < 4 * tile_width
    assert 1 / 4.0 < inverse_focus_per_m < 1 / 2.0
    assert 0.005 < radius_m < 0.03
