"""Samplers and disk mappings: what each promises, checked."""

import numpy as np
import pytest
from scipy import stats

from lenscompare import _native
from lenscompare._native import diagnostics


def pixel_samples(sampler, spp, seed=0, pixel=0):
    film, lens = np.zeros((spp, 2), np.float32), np.zeros((spp, 2), np.float32)
    diagnostics.pixel_samples(sampler, seed, pixel, film, lens)
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


_MASK64 = (1 << 64) - 1


def _mix64(z):
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & _MASK64
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & _MASK64
    return z ^ (z >> 31)


class _Pcg32:
    """PCG32 (O'Neill 2014, XSH RR) one step at a time, seeded as rng.h seeds it."""

    def __init__(self, seed, stream, dimension):
        self.state = 0
        self.inc = ((_mix64(stream ^ ((dimension * 0x9E3779B97F4A7C15) & _MASK64)) << 1) | 1) & _MASK64
        self.next_u32()
        self.state = (self.state + _mix64((seed + 0x632BE59BD9B4E019) & _MASK64)) & _MASK64
        self.next_u32()

    def next_u32(self):
        old = self.state
        self.state = (old * 6364136223846793005 + self.inc) & _MASK64
        xorshifted = (((old >> 18) ^ old) >> 27) & 0xFFFFFFFF
        rot = old >> 59
        return ((xorshifted >> rot) | (xorshifted << ((32 - rot) & 31))) & 0xFFFFFFFF


@pytest.mark.parametrize("kernel", diagnostics.rng_kernels())
def test_every_rng_kernel_draws_pcg32_one_step_at_a_time(kernel):
    """Each kernel steps several PCG states side by side (rng_lanes.cpp); every
    one must give PCG32's own outputs in order, for any count (whole leaps,
    a remainder, fewer than one leap; AVX-512 and AVX2 step two registers of
    eight, so 8, 15, 16, 17, 24 and 31 to 33 take each of its branches)."""
    for n in (1, 3, 7, 8, 9, 15, 16, 17, 24, 31, 32, 33, 63, 64, 129):
        out = np.zeros(n, np.uint32)
        diagnostics.pcg32_draws(11, 4242, 3, out, kernel)
        rng = _Pcg32(11, 4242, 3)
        assert out.tolist() == [rng.next_u32() for _ in range(n)]


def _kensler_hash(i, w, p):
    """Kensler 2013's permutation step (pbrt-v4's PermutationElement), in 32-bit arithmetic."""
    m = 0xFFFFFFFF
    i ^= p
    i = (i * 0xE170893D) & m
    i ^= p >> 16
    i ^= (i & w) >> 4
    i ^= p >> 8
    i = (i * 0x0929EB3F) & m
    i ^= p >> 23
    i ^= (i & w) >> 1
    i = (i * (1 | p >> 27)) & m
    i = (i * 0x6935FA69) & m
    i ^= (i & w) >> 11
    i = (i * 0x74DCB303) & m
    i ^= (i & w) >> 2
    i = (i * 0x9E501CC3) & m
    i ^= (i & w) >> 2
    i = (i * 0xC860A3DF) & m
    i &= w
    i ^= i >> 5
    return i


def _hashed_permutation(n, p):
    w = (1 << max(n - 1, 0).bit_length()) - 1
    out = []
    for i in range(n):
        j = _kensler_hash(i, w, p)
        while j >= n:
            j = _kensler_hash(j, w, p)
        out.append((j + p) % n)
    return out


@pytest.mark.parametrize("n", [1, 2, 7, 12, 64, 97, 100, 1024])
def test_hashed_permutation_is_a_permutation(n):
    for p in (0, 1, 0xDEADBEEF, 0xFFFFFFFF):
        assert sorted(_hashed_permutation(n, p)) == list(range(n))


def test_jittered_lens_pairing_is_uniform_over_permutations():
    """The lens strata's pairing with the film's: over many pixels, each film
    stratum meets each lens stratum equally often (chi-square), and the pairing
    differs from pixel to pixel."""
    spp, pixels = 16, 4000
    counts = np.zeros((spp, spp), int)
    pairings = set()
    for pixel in range(pixels):
        film, lens = pixel_samples(_native.SAMPLER_JITTERED, spp, seed=3, pixel=pixel)
        film_cell = (np.floor(film * 4).astype(int) @ [1, 4]).tolist()
        lens_cell = (np.floor(lens * 4).astype(int) @ [1, 4]).tolist()
        for f, l in zip(film_cell, lens_cell):
            counts[f, l] += 1
        pairings.add(tuple(lens_cell[i] for i in np.argsort(film_cell)))
    assert stats.chisquare(counts.ravel()).pvalue > 1e-3
    # Kensler's hash reaches fewer permutations than a Fisher-Yates shuffle (at 16 spp
    # 3549 of these 4000 pixels are distinct, against about 4000 for the shuffle).
    assert len(pairings) > 0.85 * pixels


# The strata: the largest divisor of spp not above its square root (searched
# downward from the root natively), primes and near-squares too.
@pytest.mark.parametrize("spp, nx, ny", [(64, 8, 8), (12, 4, 3), (7, 7, 1), (2, 2, 1), (1, 1, 1), (48, 8, 6),
                                         (97, 97, 1), (120, 12, 10), (1000, 40, 25), (1023, 33, 31),
                                         (1024, 32, 32)])
def test_jittered_draws_pcg32_one_step_at_a_time(spp, nx, ny):
    """The render draws its random numbers four PCG states at a time
    (Pcg32::fill_u32, a leap of four steps per state); the numbers must be
    PCG32's own sequence, in order: film and lens strata, then the lens pairing's number."""
    seed, pixel = 7, 123
    film, lens = pixel_samples(_native.SAMPLER_JITTERED, spp, seed=seed, pixel=pixel)
    expected = {}
    for name, stream in (("film", 0), ("lens", 1)):
        rng = _Pcg32(seed, pixel, stream)
        points = np.zeros((spp, 2), np.float32)
        for iy in range(ny):
            for ix in range(nx):
                u, v = (np.float32(rng.next_u32() >> 8) * np.float32(2.0**-24) for _ in range(2))
                points[iy * nx + ix] = (np.float32(ix) + u) / np.float32(nx), (np.float32(iy) + v) / np.float32(ny)
        expected[name] = points
        if name == "lens":  # lens stratum j goes to sample permutation(j), hashed from the next number
            paired = np.zeros_like(points)
            paired[_hashed_permutation(spp, rng.next_u32())] = points
            expected[name] = paired
    np.testing.assert_array_equal(film, expected["film"])
    np.testing.assert_array_equal(lens, expected["lens"])


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
    diagnostics.map_to_disk(u, mapping, out)
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
    diagnostics.map_to_disk(u, _native.DISK_CONCENTRIC, out)
    np.testing.assert_allclose(np.hypot(out[:, 0], out[:, 1]), [0, 1, 1, 1], atol=1e-6)


# --- All samplers: the shared contract ------------------------------------------------------------------------------

SAMPLER_CODES = {
    "random": _native.SAMPLER_RANDOM, "jittered": _native.SAMPLER_JITTERED, "regular": _native.SAMPLER_REGULAR,
    "poisson": _native.SAMPLER_POISSON, "sobol": _native.SAMPLER_SOBOL,
}


def strata(spp):
    """nx, ny of the jittered and regular grids (native jittered_strata)."""
    ny = max(d for d in range(1, int(np.sqrt(spp)) + 1) if spp % d == 0)
    return spp // ny, ny


def test_every_sampler_is_offered_by_scene_files_and_the_renderer():
    from lenscompare.render import SAMPLER_CODES as render_codes
    from lenscompare.scene import SAMPLERS
    assert SAMPLERS[:2] == ("random", "jittered")
    assert set(SAMPLERS) == set(SAMPLER_CODES) == set(render_codes)
    assert render_codes == SAMPLER_CODES


@pytest.mark.parametrize("name", SAMPLER_CODES)
@pytest.mark.parametrize("spp", [1, 7, 64, 100, 1024])
def test_every_sampler_fills_the_unit_square_the_same_way_for_the_same_seed(name, spp):
    film, lens = pixel_samples(SAMPLER_CODES[name], spp, seed=11, pixel=1234)
    for points in (film, lens):
        assert np.all((points >= 0) & (points < 1))
    again = pixel_samples(SAMPLER_CODES[name], spp, seed=11, pixel=1234)
    assert np.array_equal(film, again[0]) and np.array_equal(lens, again[1])
    if name != "regular" and spp > 1:  # regular is the same grid everywhere, by design
        for other in (pixel_samples(SAMPLER_CODES[name], spp, seed=12, pixel=1234),
                      pixel_samples(SAMPLER_CODES[name], spp, seed=11, pixel=1235)):
            assert not np.array_equal(film, other[0]) and not np.array_equal(lens, other[1])


@pytest.mark.parametrize("name", ["regular", "poisson", "sobol"])
def test_renders_do_not_depend_on_the_thread_count(name):
    """Two threads first, so poisson's patterns for this spp are made concurrently."""
    from lenscompare.render import render
    from lenscompare.scene import load_scene
    from helpers import REFERENCE_SCENES
    scene = load_scene(REFERENCE_SCENES / "showcase.toml").with_camera(resolution=(120, 80))
    two = render(scene, model="thin", sampler=name, spp=24, seed=7, threads=2, progress=False)
    one = render(scene, model="thin", sampler=name, spp=24, seed=7, threads=1, progress=False)
    assert one.pixels.tobytes() == two.pixels.tobytes()
    assert np.all(np.isfinite(one.pixels))


# --- Film/lens decorrelation and discrepancy -------------------------------------------------------------------------

@pytest.mark.parametrize("name", ["random", "jittered", "poisson", "sobol"])  # regular: its own test below
def test_film_and_lens_are_decorrelated(name):
    """Film point i and lens point i form one camera sample: no coordinate of one may predict the other.

    Pooled over 300 pixels the correlation must vanish (|r| < 4 standard errors); per pixel its spread must be
    that of independent points (RMS about 1/sqrt(spp)), not larger — a larger spread would mean film and lens
    are tied within a pixel with a sign that changes from pixel to pixel.
    """
    spp, pixels = 64, 300
    film, lens = zip(*(pixel_samples(SAMPLER_CODES[name], spp, seed=4, pixel=p) for p in range(pixels)))
    film, lens = np.array(film, float), np.array(lens, float)
    for f_axis, l_axis in [(0, 0), (1, 1), (0, 1), (1, 0)]:
        f, l = film[:, :, f_axis], lens[:, :, l_axis]
        pooled = np.corrcoef(f.ravel(), l.ravel())[0, 1]
        assert abs(pooled) < 4 / np.sqrt(spp * pixels), (f_axis, l_axis, pooled)
        fc, lc = f - f.mean(axis=1, keepdims=True), l - l.mean(axis=1, keepdims=True)
        per_pixel = (fc * lc).sum(1) / np.sqrt((fc ** 2).sum(1) * (lc ** 2).sum(1))
        assert np.sqrt(np.mean(per_pixel ** 2)) < 1.25 / np.sqrt(spp), (f_axis, l_axis)


def l2_star_discrepancy(points):
    """L2 star discrepancy of points in [0,1)^2, exactly (Warnock 1972)."""
    p = np.asarray(points, float)
    n = len(p)
    term1 = np.prod((1 - p ** 2) / 2, axis=1).sum()
    term2 = np.prod(1 - np.maximum(p[:, None, :], p[None, :, :]), axis=2).sum()
    return np.sqrt(1 / 9 - 2 / n * term1 + term2 / n ** 2)


def test_l2_star_discrepancy_of_the_formula_on_known_sets():
    # One point at the origin: integral over anchored boxes of (1 - xy)^2 = 1 - 1/2 + 1/9.
    assert l2_star_discrepancy([[0.0, 0.0]]) == pytest.approx(np.sqrt(1 - 0.5 + 1 / 9))
    # Brute force on a fine grid of box corners for a small random set
    p = np.random.default_rng(1).random((5, 2))
    t = (np.arange(400) + 0.5) / 400
    inside = (p[:, 0][:, None, None] < t[None, :, None]) & (p[:, 1][:, None, None] < t[None, None, :])
    brute = np.sqrt(np.mean((inside.mean(0) - t[:, None] * t[None, :]) ** 2))
    assert l2_star_discrepancy(p) == pytest.approx(brute, rel=0.01)


@pytest.mark.parametrize("spp", [16, 64, 256])
def test_stratified_and_low_discrepancy_samplers_beat_random(spp):
    """Mean L2 star discrepancy over pixels (film and lens sets): at most 0.7 of random's."""
    def mean_discrepancy(name):
        sets = [s for p in range(100) for s in pixel_samples(SAMPLER_CODES[name], spp, seed=3, pixel=p)]
        return np.mean([l2_star_discrepancy(s) for s in sets])

    random = mean_discrepancy("random")
    found = {name: mean_discrepancy(name) for name in ["jittered", "poisson", "sobol"]}
    print(f"L2* discrepancy at {spp} spp: random {random:.4f}, "
          + ", ".join(f"{k} {v:.4f}" for k, v in found.items()))
    for name, value in found.items():
        assert value < 0.7 * random, name


# --- regular ---------------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("spp", [1, 7, 12, 16, 64, 100, 128])
def test_regular_is_the_grid_of_stratum_centres_in_every_pixel(spp):
    nx, ny = strata(spp)
    ix, iy = np.meshgrid(np.arange(nx), np.arange(ny))
    centres = np.stack([(ix.ravel() + 0.5) / nx, (iy.ravel() + 0.5) / ny], axis=1).astype(np.float32)
    film, lens = pixel_samples(_native.SAMPLER_REGULAR, spp)
    np.testing.assert_array_equal(film, centres)  # row by row, exactly
    np.testing.assert_array_equal(np.unique(lens, axis=0), np.unique(centres, axis=0))  # the same cells, reordered
    for seed, pixel in [(1, 0), (0, 99), (5, 12345)]:
        other = pixel_samples(_native.SAMPLER_REGULAR, spp, seed=seed, pixel=pixel)
        assert np.array_equal(film, other[0]) and np.array_equal(lens, other[1])


@pytest.mark.parametrize("spp", [16, 36, 64, 100, 128, 256, 1024])
def test_regular_pairs_every_film_column_with_many_lens_columns(spp):
    """The fixed lens order: every film column meets ny lens columns, every film row all ny lens rows, and no
    film coordinate is correlated with a lens coordinate beyond 3 / sqrt(spp)."""
    nx, ny = strata(spp)
    film, lens = pixel_samples(_native.SAMPLER_REGULAR, spp)
    assert len({(a, b) for a, b in zip(film[:, 0], lens[:, 0])}) == spp
    assert len({(a, b) for a, b in zip(film[:, 1], lens[:, 1])}) == ny * ny
    for f_axis in range(2):
        for l_axis in range(2):
            assert abs(np.corrcoef(film[:, f_axis], lens[:, l_axis])[0, 1]) < 3 / np.sqrt(spp)


# --- poisson ---------------------------------------------------------------------------------------------------------

def min_torus_distance(points):
    d = np.abs(points[:, None, :].astype(float) - points[None, :, :])
    d = np.minimum(d, 1 - d)
    d = np.hypot(d[..., 0], d[..., 1])
    np.fill_diagonal(d, np.inf)
    return d.min()


@pytest.mark.parametrize("spp, pixels", [(2, 100), (5, 100), (9, 100), (16, 100), (64, 150), (256, 100),
                                         (1024, 8)])
def test_poisson_keeps_a_minimum_distance(spp, pixels):
    """Minimum pairwise distance on the torus (so across the square's edges too, which is stricter than in the
    square) of every pixel's film and lens set: at least 0.6 of the spacing of spp points in a hexagonal packing
    of the unit square, sqrt(2 / (sqrt(3) spp)), the largest any spp points can keep. Measured: 0.67 to 0.72."""
    ideal = np.sqrt(2 / (np.sqrt(3) * spp))
    worst = min(min_torus_distance(s) for p in range(pixels)
                for s in pixel_samples(_native.SAMPLER_POISSON, spp, seed=2, pixel=p))
    assert worst >= 0.6 * ideal, worst / ideal
    # ...which independent points do not come near
    if spp >= 16:
        assert min_torus_distance(pixel_samples(_native.SAMPLER_RANDOM, spp, seed=2)[0]) < 0.6 * ideal


def test_poisson_points_are_uniform_over_pixels():
    """Each pixel's pattern is shifted uniformly on the torus, so pooled points are uniform (no bias)."""
    sets = [s for p in range(300) for s in pixel_samples(_native.SAMPLER_POISSON, 64, seed=8, pixel=p)]
    pooled = np.concatenate(sets)
    for axis in range(2):
        assert stats.kstest(pooled[:, axis], "uniform").pvalue > 1e-3
    firsts = np.array([s[0] for s in sets])  # the i-th point alone, too
    for axis in range(2):
        assert stats.kstest(firsts[:, axis], "uniform").pvalue > 1e-3


# --- sobol -----------------------------------------------------------------------------------------------------------

def is_02_net(points, m):
    """Every elementary interval [a/2^i, (a+1)/2^i) x [b/2^j, (b+1)/2^j), i + j = m, holds exactly one point."""
    return len(points) == 2 ** m and holds_at_most_one_per_interval(points, m)


def holds_at_most_one_per_interval(points, m):
    return holds_at_most_2t_per_interval(points, m, t=0)


def compositions(total, parts):
    """Every way to write total as an ordered sum of parts integers >= 0."""
    if parts == 1:
        yield (total,)
        return
    for first in range(total + 1):
        for rest in compositions(total - first, parts - 1):
            yield (first, *rest)


def holds_at_most_2t_per_interval(points, m, t):
    """Every elementary interval of volume 2^(t - m) (any number of dimensions) holds at most 2^t points."""
    p = np.asarray(points, float)
    for bits in compositions(max(m - t, 0), p.shape[1]):
        cells = np.zeros(len(p), np.int64)
        for axis, b in enumerate(bits):
            cells = cells * 2 ** b + np.floor(p[:, axis] * 2 ** b).astype(np.int64)
        if np.bincount(cells).max() > 2 ** t:
            return False
    return True


def is_t_net(points, m, t):
    """A (t, m, d)-net in base 2: 2^m points, 2^t in every elementary interval of volume 2^(t - m)."""
    return len(points) == 2 ** m and holds_at_most_2t_per_interval(points, m, t)


def test_net_check_rejects_random_points():
    assert not is_02_net(pixel_samples(_native.SAMPLER_RANDOM, 64)[0], 6)


@pytest.mark.parametrize("m", range(11))
def test_unscrambled_sobol_is_scipys_sobol_and_a_02_net(m):
    from scipy.stats import qmc
    film, lens = pixel_samples(diagnostics.SAMPLER_SOBOL_UNSCRAMBLED, 2 ** m, seed=5, pixel=17)
    assert np.array_equal(film, lens)
    assert is_02_net(film, m)
    reference = qmc.Sobol(d=2, scramble=False).random_base2(m)  # same points, Gray-code order
    np.testing.assert_array_equal(np.unique(film, axis=0), np.unique(reference.astype(np.float32), axis=0))


@pytest.mark.parametrize("m", range(11))
def test_scrambled_sobol_film_lens_and_both_together_are_nets_in_every_pixel(m):
    """Film points: Sobol' dimensions 0-1, a (0,m,2)-net. Lens points: dimensions
    2-3, a (1,m,2)-net (a (2,3,2)-net at 8 points). Together, dimensions 0-3 are
    a (3,m,4)-net: film and lens are stratified jointly, which a random pairing
    of the two is not."""
    sets = [pixel_samples(_native.SAMPLER_SOBOL, 2 ** m, seed=6, pixel=p) for p in range(20)]
    lens_t = 2 if m == 3 else min(m, 1)
    assert all(is_t_net(film, m, 0) and is_t_net(lens, m, lens_t) for film, lens in sets)
    assert all(is_t_net(np.hstack([film, lens]), m, min(m, 3)) for film, lens in sets)
    if m >= 2:  # and the scrambles differ from pixel to pixel, and between film and lens
        flat = [s.tobytes() for pair in sets for s in pair]
        assert len(set(flat)) == len(flat)


def test_joint_net_check_rejects_independently_paired_film_and_lens():
    film, lens = pixel_samples(_native.SAMPLER_JITTERED, 256, seed=6, pixel=3)
    assert not is_t_net(np.hstack([film, lens]), 8, 3)


@pytest.mark.parametrize("spp", [3, 12, 100, 700])
def test_sobol_first_points_for_other_spp_share_no_interval_of_the_next_net(spp):
    """spp points taken from a 2^m-point net (2^m the next power of two): no
    elementary interval holds more than the net allows."""
    m = int(np.ceil(np.log2(spp)))
    for p in range(10):
        film, lens = pixel_samples(_native.SAMPLER_SOBOL, spp, seed=1, pixel=p)
        assert holds_at_most_2t_per_interval(film, m, 0)
        assert holds_at_most_2t_per_interval(lens, m, 1)
        assert holds_at_most_2t_per_interval(np.hstack([film, lens]), m, 3)


@pytest.mark.parametrize("mapping", [_native.DISK_POLAR, _native.DISK_CONCENTRIC])
def test_sobol_lens_points_are_uniform_on_the_disk(mapping):
    """Chi-square over equal-area cells (rings x sectors), as for the mappings themselves."""
    u = np.concatenate([pixel_samples(_native.SAMPLER_SOBOL, 64, seed=9, pixel=p)[1] for p in range(600)])
    out = np.zeros_like(u)
    diagnostics.map_to_disk(u, mapping, out)
    r = np.hypot(out[:, 0], out[:, 1])
    rings, sectors = 5, 8
    ring = np.minimum((r ** 2 * rings).astype(int), rings - 1)
    sector = ((np.arctan2(out[:, 1], out[:, 0]) + np.pi) / (2 * np.pi) * sectors).astype(int) % sectors
    counts = np.bincount(ring * sectors + sector, minlength=rings * sectors)
    assert stats.chisquare(counts).pvalue > 1e-3


@pytest.mark.parametrize("name", sorted(SAMPLER_CODES))
@pytest.mark.parametrize("first_sample", [0, 16])
def test_a_pixel_without_lens_points_has_the_same_film_time_and_wavelength(name, first_sample):
    """The pinhole's render draws no lens points (random and jittered skip
    their stream, the others make them into scratch): nothing else may move."""
    spp = 32
    for pixel in (0, 5, 77):
        drawn = [np.zeros((spp, 2), np.float32), np.zeros((spp, 2), np.float32), np.zeros(spp, np.float32),
                 np.zeros(spp, np.float32)]
        skipped = [np.zeros((spp, 2), np.float32), None, np.zeros(spp, np.float32), np.zeros(spp, np.float32)]
        for film, lens, time, wavelength in (drawn, skipped):
            diagnostics.pixel_samples(SAMPLER_CODES[name], 4, pixel, film, lens, time, wavelength,
                                      first_sample=first_sample)
        for a, b in zip(drawn, skipped):
            if b is not None:
                assert a.tobytes() == b.tobytes(), (name, pixel)
        assert np.any(drawn[1] != 0.0)  # the lens points were drawn in the first call


def test_poisson_patterns_made_ahead_are_the_patterns_made_on_first_use():
    """prepare_poisson_patterns (render's warm-up, outside its time) makes the pool that first use would:
    the pixels' samples are the same either way, and a render at that spp then reports no set-up."""
    from lenscompare.render import render
    from lenscompare.scene import load_scene

    from helpers import REFERENCE_SCENES

    spp = 37  # a count no other test draws, so its pool is made here
    lazily = [pixel_samples(_native.SAMPLER_POISSON, spp, seed=5, pixel=p) for p in range(40)]
    _native.prepare_poisson_patterns(spp)
    ahead = [pixel_samples(_native.SAMPLER_POISSON, spp, seed=5, pixel=p) for p in range(40)]
    for (film_a, lens_a), (film_b, lens_b) in zip(lazily, ahead):
        assert np.array_equal(film_a, film_b) and np.array_equal(lens_a, lens_b)
    scene = load_scene(REFERENCE_SCENES / "showcase.toml").with_camera(resolution=(24, 16)).with_render(
        spp=41, sampler="poisson")
    first, second = (render(scene, model="pinhole", seed=1, threads=1, progress=False) for _ in range(2))
    assert first.metadata["sampler_setup_seconds"] > 0 and second.metadata["sampler_setup_seconds"] < 1e-3
    assert np.array_equal(first.pixels, second.pixels)
