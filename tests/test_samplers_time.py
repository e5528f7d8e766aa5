"""Time as a sample dimension: what each sampler promises for it, checked."""

import numpy as np
import pytest
from scipy import stats
from scipy.stats import qmc

from lenscompare import _native
from lenscompare._native import diagnostics

SAMPLERS = {"random": _native.SAMPLER_RANDOM, "jittered": _native.SAMPLER_JITTERED,
            "regular": _native.SAMPLER_REGULAR, "poisson": _native.SAMPLER_POISSON, "sobol": _native.SAMPLER_SOBOL}


def samples(sampler, spp, *, seed=0, pixel=0, with_time=True):
    film, lens = np.zeros((spp, 2), np.float32), np.zeros((spp, 2), np.float32)
    time = np.zeros(spp, np.float32) if with_time else None
    diagnostics.pixel_samples(sampler, seed, pixel, film, lens, time)
    return film, lens, time


@pytest.mark.parametrize("name", SAMPLERS)
def test_drawing_times_changes_no_film_or_lens_point(name):
    """The static path's samples are the moving path's film and lens samples."""
    for pixel in range(5):
        film, lens, _ = samples(SAMPLERS[name], 64, seed=9, pixel=pixel)
        film0, lens0, _ = samples(SAMPLERS[name], 64, seed=9, pixel=pixel, with_time=False)
        assert np.array_equal(film, film0) and np.array_equal(lens, lens0)


@pytest.mark.parametrize("name", ["jittered", "regular", "poisson", "sobol"])
@pytest.mark.parametrize("spp", [16, 64, 100])
def test_times_are_stratified(name, spp):
    """One time in each interval [k/spp, (k+1)/spp) (sobol: for power-of-two spp,
    the (0,1)-net property of one scrambled Sobol' dimension)."""
    if name == "sobol" and spp & (spp - 1):
        pytest.skip("a Sobol' prefix of 100 points is stratified only within its 64-point nets")
    for pixel in range(10):
        _, _, time = samples(SAMPLERS[name], spp, seed=3, pixel=pixel)
        assert np.all((time >= 0) & (time < 1))
        assert sorted(np.floor(time * spp).astype(int).tolist()) == list(range(spp))


@pytest.mark.parametrize("name", ["jittered", "regular", "poisson"])
def test_times_are_decorrelated_from_film_and_lens(name):
    """Pairing by permutation: no coordinate of film or lens predicts the time."""
    correlations = []
    for pixel in range(40):
        film, lens, time = samples(SAMPLERS[name], 64, seed=1, pixel=pixel)
        for column in (film[:, 0], film[:, 1], lens[:, 0], lens[:, 1]):
            correlations.append(np.corrcoef(column, time)[0, 1])
    bound = 3 / np.sqrt(64)
    assert np.max(np.abs(correlations)) < bound if name == "regular" else np.mean(np.abs(correlations)) < bound / 2


def test_random_times_are_uniform_and_seeded():
    _, _, time = samples(SAMPLERS["random"], 20000, seed=5)
    assert stats.kstest(time, "uniform").pvalue > 1e-3
    _, _, other = samples(SAMPLERS["random"], 20000, seed=6)
    assert not np.array_equal(time, other)


def test_sobol_time_is_dimension_6_of_the_joe_kuo_sequence():
    """The unscrambled time points are SciPy's seventh Sobol' dimension (SciPy reads
    the same new-joe-kuo-6.21201 direction numbers, and yields points in Gray-code
    order: point i of SciPy is point i ^ (i >> 1) of ours)."""
    spp = 256
    _, _, time = samples(diagnostics.SAMPLER_SOBOL_UNSCRAMBLED, spp)
    scipy_points = qmc.Sobol(d=7, scramble=False).random(spp)
    gray = np.arange(spp) ^ (np.arange(spp) >> 1)
    assert np.allclose(time[gray], scipy_points[:, 6], atol=2 ** -24)


@pytest.mark.parametrize("pixel", [0, 17, 4242])
def test_sobol_lens_and_time_fill_every_cell_at_64_spp(pixel):
    """Why time is dimension 6: with 64 samples, lens-u x time and lens-v x time
    each put one sample in every cell of an 8 x 8 grid, and lens x time one in
    every cell of 4 x 4 x 4 (dimension 4 filled 32 of 64 in both), while film x
    time still fills all of 4 x 4 x 4."""
    film, lens, time = samples(_native.SAMPLER_SOBOL, 64, seed=3, pixel=pixel)
    def cells(*columns):
        bits = {2: 3, 3: 2}[len(columns)]
        index = sum(np.floor(c * 2 ** bits).astype(int) << (bits * k) for k, c in enumerate(columns))
        return len(np.unique(index))
    assert cells(lens[:, 0], time) == 64
    assert cells(lens[:, 1], time) == 64
    assert cells(lens[:, 0], lens[:, 1], time) == 64
    assert cells(film[:, 0], film[:, 1], time) == 64


def test_sobol_film_lens_time_form_one_net():
    """Jointly stratified: with 64 points, each box of volume 1/64 of these
    shapes over film y, lens u and time (dimensions 1, 2 and 6) holds one point;
    padding (each group alone, paired at random) leaves them unevenly filled.
    (Film x, lens u and time are not: 4 x 4 x 4 holds 16 boxes of 4 points,
    bench/study_sobol_time_dimension.py.)"""
    spp = 64
    def worst_box_count_error(sampler):
        worst = 0
        for pixel in range(20):
            film, lens, time = samples(sampler, spp, seed=2, pixel=pixel)
            points = np.stack([film[:, 1], lens[:, 0], time], axis=1)
            for bits in ((2, 2, 2), (1, 2, 3), (3, 1, 2), (2, 3, 1)):  # 64 boxes of 1/64
                index = sum((np.floor(points[:, k] * 2 ** b).astype(int) << sum(bits[k + 1:]))
                            for k, b in enumerate(bits))
                counts = np.bincount(index, minlength=spp)
                worst = max(worst, int(np.abs(counts - 1).max()))
        return worst
    assert worst_box_count_error(_native.SAMPLER_SOBOL) <= 1
    assert worst_box_count_error(diagnostics.SAMPLER_SOBOL_PADDED) >= 2
