"""Samplers and disk mappings: what each promises, checked."""

import numpy as np
import pytest
from scipy import stats

from lenscompare import _native


def pixel_samples(sampler, spp, seed=0, pixel=0):
    film, lens = np.zeros((spp, 2), np.float32), np.zeros((spp, 2), np.float32)
    _native.pixel_samples(sampler, seed, pixel, film, lens)
    return film, lens


@pytest.mark.parametrize("spp, nx, ny", [(64, 8, 8), (128, 16, 8), (12, 4, 3), (7, 7, 1)])
def test_jittered_has_one_sample_per_stratum(spp, nx, ny):
    for pixel in range(20):
        for points in pixel_samples(_native.SAMPLER_JITTERED, spp, pixel=pixel):
            assert np.all((points >= 0) & (points < 1))
            cells = np.floor(points[:, 0] * nx).astype(int) + nx * np.floor(points[:, 1] * ny).astype(int)
            assert sorted(cells.tolist()) == list(range(spp))


def test_jittered_lens_is_shuffled_against_film():
    film, lens = pixel_samples(_native.SAMPLER_JITTERED, 64, pixel=3)
    film_cell = np.floor(film * 8).astype(int) @ [1, 8]
    lens_cell = np.floor(lens * 8).astype(int) @ [1, 8]
    assert not np.array_equal(film_cell, lens_cell)


def test_random_is_uniform_and_seeded():
    film, lens = pixel_samples(_native.SAMPLER_RANDOM, 20000, seed=5)
    for points in (film, lens):
        for axis in range(2):
            assert stats.kstest(points[:, axis], "uniform").pvalue > 1e-3
    again, _ = pixel_samples(_native.SAMPLER_RANDOM, 20000, seed=5)
    other, _ = pixel_samples(_native.SAMPLER_RANDOM, 20000, seed=6)
    assert np.array_equal(film, again) and not np.array_equal(film, other)


@pytest.mark.parametrize("mapping", [_native.DISK_POLAR, _native.DISK_CONCENTRIC])
def test_disk_mappings_are_uniform_on_the_disk(mapping):
    """Chi-square over equal-area cells (rings x sectors) of the unit disk."""
    u = np.random.default_rng(2).random((40000, 2)).astype(np.float32)
    out = np.zeros_like(u)
    _native.map_to_disk(u, mapping, out)
    r = np.hypot(out[:, 0], out[:, 1])
    assert r.max() <= 1.0 + 1e-6
    rings, sectors = 5, 8
    ring = np.minimum((r ** 2 * rings).astype(int), rings - 1)  # equal-area rings
    sector = ((np.arctan2(out[:, 1], out[:, 0]) + np.pi) / (2 * np.pi) * sectors).astype(int) % sectors
    counts = np.bincount(ring * sectors + sector, minlength=rings * sectors)
    assert stats.chisquare(counts).pvalue > 1e-3


def test_concentric_maps_square_edges_to_the_circle_and_centre_to_centre():
    u = np.array([[0.5, 0.5], [1.0, 0.5], [0.5, 0.0], [0.0, 0.0]], np.float32)
    out = np.zeros_like(u)
    _native.map_to_disk(u, _native.DISK_CONCENTRIC, out)
    np.testing.assert_allclose(np.hypot(out[:, 0], out[:, 1]), [0, 1, 1, 1], atol=1e-6)
