"""Time as a sample dimension: what each sampler promises for it, checked."""

import itertools

import numpy as np
import pytest
from scipy import stats
from scipy.stats import qmc

from lenscompare import _native
from lenscompare._native import diagnostics

SAMPLERS = {"random": _native.SAMPLER_RANDOM, "jittered": _native.SAMPLER_JITTERED,
            "regular": _native.SAMPLER_REGULAR, "poisson": _native.SAMPLER_POISSON, "sobol": _native.SAMPLER_SOBOL}


def samples(sampler, spp, *, seed=0, pixel=0, with_time=True, first_sample=0):
    """One pixel's samples as a render pass taking samples [first_sample, spp) draws them."""
    film, lens = np.zeros((spp, 2), np.float32), np.zeros((spp, 2), np.float32)
    time = np.zeros(spp, np.float32) if with_time else None
    diagnostics.pixel_samples(sampler, seed, pixel, film, lens, time, first_sample=first_sample)
    return film, lens, time


def occupied_boxes(columns, bits) -> int:
    """How many elementary boxes, bits[k] bits deep in columns[k], hold a sample."""
    index = np.zeros(len(columns[0]), dtype=np.int64)
    for column, b in zip(columns, bits):
        index = (index << b) | np.floor(column * 2 ** b).astype(np.int64)
    return len(np.unique(index))


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
        pytest.skip("Owen-scrambled times (i / 100, or a Sobol' prefix) are stratified in power-of-two intervals only")
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


@pytest.mark.parametrize("spp", [16, 64])
@pytest.mark.parametrize("pixel", [0, 17, 4242])
def test_sobol_whole_pixel_film_and_time_are_one_net(pixel, spp):
    """A pixel drawn whole (first sample 0) takes time i / spp, Owen-scrambled:
    film x, film y and time are then a (0,m,3)-net, one sample in every
    elementary box of volume 1 / spp (tests/test_sobol_time_net.py)."""
    film, _, time = samples(_native.SAMPLER_SOBOL, spp, seed=3, pixel=pixel)
    m = spp.bit_length() - 1
    for a, b in itertools.product(range(m + 1), repeat=2):
        if m - a - b >= 0:
            assert occupied_boxes([film[:, 0], film[:, 1], time], (a, b, m - a - b)) == spp, (a, b)


def test_sobol_continuation_time_is_dimension_6():
    """An adaptive pass that continues a pixel (first sample > 0) takes time from
    dimension 6 instead, which does not depend on the pass's end: i / end over
    [first, end) would cover only the shutter's last part. Owen scrambling keeps
    how many elementary boxes the points fill, so film x time fills as many as
    the unscrambled dimensions 0 and 6 do, fewer than the whole-pixel net."""
    spp, shapes = 64, [(3, 3), (2, 4), (4, 2)]
    bare_film, _, bare_time = samples(diagnostics.SAMPLER_SOBOL_UNSCRAMBLED, spp)
    bare = [occupied_boxes([bare_film[:, 0], bare_time], bits) for bits in shapes]
    assert min(bare) < spp
    for pixel in range(5):
        film, _, time = samples(_native.SAMPLER_SOBOL, spp, seed=3, pixel=pixel, first_sample=16)
        assert [occupied_boxes([film[:, 0], time], bits) for bits in shapes] == bare
        _, _, longer = samples(_native.SAMPLER_SOBOL, 2 * spp, seed=3, pixel=pixel, first_sample=spp)
        assert np.array_equal(longer[:spp], time)  # extensible: the prefix stays
        _, _, whole = samples(_native.SAMPLER_SOBOL, spp, seed=3, pixel=pixel)
        assert [occupied_boxes([film[:, 0], whole], bits) for bits in shapes] == [spp] * 3
        assert sorted(np.floor(time[16:32] * 16).astype(int).tolist()) == list(range(16))  # one Sobol' block


@pytest.mark.parametrize("first_sample", [0, 32])
@pytest.mark.parametrize("pixel", [0, 17, 4242])
def test_sobol_lens_and_time_fill_every_cell_at_64_spp(pixel, first_sample):
    """With 64 samples, lens-u x time and lens-v x time each put one sample in
    every cell of an 8 x 8 grid, and lens x time one in every cell of 4 x 4 x 4,
    with time i / spp (a whole pixel) as with dimension 6 (a continuation;
    dimension 4 filled 32 of 64 in both), and film x time all of 4 x 4 x 4."""
    film, lens, time = samples(_native.SAMPLER_SOBOL, 64, seed=3, pixel=pixel, first_sample=first_sample)
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
    shapes over film y, lens u and time holds one point, whether a pixel is
    drawn whole (time i / 64) or continued (time from dimension 6); padding
    (each group alone, paired at random) leaves them unevenly filled. Over film
    x, lens u and time, 4 x 4 x 4 holds one point per box with time i / 64 but
    16 boxes of 4 points with dimension 6 (bench/study_sobol_time_dimension.py)."""
    spp, shapes = 64, ((2, 2, 2), (1, 2, 3), (3, 1, 2), (2, 3, 1))  # 64 boxes of 1/64 each
    def worst_box_count_error(sampler, film_column, first_sample=0):
        worst = dict.fromkeys(shapes, 0)
        for pixel in range(20):
            film, lens, time = samples(sampler, spp, seed=2, pixel=pixel, first_sample=first_sample)
            points = np.stack([film[:, film_column], lens[:, 0], time], axis=1)
            for bits in shapes:
                index = sum((np.floor(points[:, k] * 2 ** b).astype(int) << sum(bits[k + 1:]))
                            for k, b in enumerate(bits))
                counts = np.bincount(index, minlength=spp)
                worst[bits] = max(worst[bits], int(np.abs(counts - 1).max()))
        return worst
    for first_sample in (0, 16):
        assert max(worst_box_count_error(_native.SAMPLER_SOBOL, 1, first_sample).values()) == 0
    assert worst_box_count_error(_native.SAMPLER_SOBOL, 0)[2, 2, 2] == 0
    assert worst_box_count_error(_native.SAMPLER_SOBOL, 0, first_sample=16)[2, 2, 2] == 3
    assert max(worst_box_count_error(diagnostics.SAMPLER_SOBOL_PADDED, 1).values()) >= 2
