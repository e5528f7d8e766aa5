"""sobol with time from the index (SAMPLER_SOBOL_TIME_NET): what the render's sobol draws for a pixel drawn whole.

Film (Sobol' dimensions 0-1, generator matrices I and Pascal) with time i / spp
(the reversal matrix) is a (0,m,3)-net in base 2 (Niederreiter 1992, the
Faure-type net): at 2^m samples every box of volume 2^-m with power-of-two
sides in film x, film y and time holds exactly one sample. Owen scrambling
keeps that. Film and lens stay the sobol sampler's own.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from lenscompare import _native
from lenscompare._native import diagnostics


def samples(sampler: int, spp: int, pixel: int = 5, first_sample: int = 0):
    film, lens = np.zeros((spp, 2), np.float32), np.zeros((spp, 2), np.float32)
    time = np.zeros(spp, np.float32)
    diagnostics.pixel_samples(sampler, 11, pixel, film, lens, time, first_sample=first_sample)
    return film, lens, time


@pytest.mark.parametrize("m", [4, 6, 8])
def test_film_and_time_are_a_zero_net(m):
    film, _, time = samples(diagnostics.SAMPLER_SOBOL_TIME_NET, 2 ** m)
    points = np.column_stack([film, time])
    for a, b in itertools.product(range(m + 1), repeat=2):
        c = m - a - b
        if c < 0:
            continue
        cells = (np.floor(points * np.array([2 ** a, 2 ** b, 2 ** c])).astype(int)
                 @ np.array([2 ** (b + c), 2 ** c, 1]))
        assert np.bincount(cells, minlength=2 ** m).max() == 1, (a, b, c)


def test_dimension_6_is_not_one():
    """sobol continuing a pixel (time from dimension 6) leaves film x time cells empty at 64 spp."""
    film, _, time = samples(_native.SAMPLER_SOBOL, 64, first_sample=16)
    cells = np.floor(film[:, 0] * 8).astype(int) * 8 + np.floor(time * 8).astype(int)
    assert len(np.unique(cells)) < 64


def test_the_render_draws_it_for_a_whole_pixel():
    """diagnostics.pixel_samples draws as the render does: sobol from sample 0 is this net."""
    for pixel in range(3):
        net, whole = samples(diagnostics.SAMPLER_SOBOL_TIME_NET, 64, pixel), samples(_native.SAMPLER_SOBOL, 64, pixel)
        assert all(np.array_equal(a, b) for a, b in zip(net, whole))


def test_film_and_lens_are_sobol_own():
    film_net, lens_net, _ = samples(diagnostics.SAMPLER_SOBOL_TIME_NET, 64)
    film, lens, _ = samples(_native.SAMPLER_SOBOL, 64, first_sample=16)
    assert np.array_equal(film_net, film) and np.array_equal(lens_net, lens)
