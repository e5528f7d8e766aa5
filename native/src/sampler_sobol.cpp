// The sobol sampler: Owen-scrambled Sobol' points in four dimensions per
// pixel, film from dimensions 0-1 and lens from dimensions 2-3, and time (when
// the scene moves) i / spp for a pixel drawn whole, or dimension 6 of the same
// sequence for an adaptive pass that continues a pixel (both Owen-scrambled).
//
// Sobol' dimensions 0 (van der Corput) and 1 form a (0,2)-sequence: every
// aligned block of 2^m consecutive points is a (0,m,2)-net, one point in each
// elementary interval [a/2^i, (a+1)/2^i) x [b/2^j, (b+1)/2^j) with i + j = m.
// Dimensions 2-3 form a (1,2)-sequence (at 8 points a (2,3,2)-net), and
// dimensions 0-3 together a (3,4)-sequence: film and lens are stratified
// jointly. A defocused edge is a function of film and lens position together,
// and on the showcase scene this joint stratification lowers the thin-lens
// image error 1.45x at 64 spp against padding (dimensions 0-1 for both, the
// lens points paired with the film points at random), which left the
// film-lens interaction at the 1/sqrt(N) rate of independent samples.
//
// A pixel takes points 0..spp-1 — for spp not a power of two, the first spp
// points, which sit inside the net of the next power of two — and scrambles
// each coordinate with a hash-based nested uniform (Owen) scramble, which
// keeps every net property, with seeds drawn per pixel. The scramble is
// Burley's ("Practical Hash-based Owen Scrambling", JCGT 9(4), 2020) with
// Vegdahl's improved hash ("Building a better LK hash", psychopath.io, 2021).
// Direction numbers: Joe & Kuo, "Constructing Sobol sequences with better
// two-dimensional projections", SIAM J. Sci. Comput. 30 (2008), file
// new-joe-kuo-6.21201 (d = 2, 3 there are dimensions 1, 2 here, and so on;
// checked against SciPy's unscrambled Sobol', which reads the same file, in
// tests/test_samplers_time.py).
//
// Wavelength (spectral renders) as dimension 5, a further dimension of the
// same net (Joe & Kuo d = 6: degree 4, a = 1, m = 1 1 3 3).
//
// Time as dimension 6 (Joe & Kuo d = 7: degree 4, a = 4, m = 1 3 5 13), so a
// moving, defocused edge (a function of film, lens and time together) is
// integrated by one jointly stratified set. Dimension 6, not 4: with 64
// points, dimension 4 fills only 32 of the 64 cells of lens-u x time on an
// 8x8 grid and of lens x time on 4x4x4, dimension 6 all 64 of both (and of
// film x time on 4x4x4); on the bench_motion.py scenes the 64-spp image error
// against padding (film, lens and time each stratified alone and paired at
// random: SobolPadded) fell 1.29x (geometric mean, ten scenes) instead of
// 1.22x. The pairs, per candidate dimension: bench/study_sobol_time_dimension.py.
//
// Time i / spp instead (time_from_index; the render's choice for a pixel drawn
// whole, render_tile.h): film (generator matrices I and Pascal) and time (the
// reversal matrix) are then a (0,m,3)-net, the Faure-type net (Niederreiter
// 1992), and lens x time still fills all 64 4x4x4 cells at 64 points; on the
// moving showcase the error against padding fell 1.34x instead of 1.21x
// (bench_motion.py). It is not extensible (a sample's time depends on spp),
// so an adaptive pass continuing samples [first, end) keeps dimension 6.
#include <cstdint>
#include <utility>

#include "rng.h"
#include "samplers.h"

namespace lc {
namespace {

constexpr uint64_t kSobolStream = 16;  // clear of the other samplers' streams
constexpr uint64_t kSobolPaddedStream = 18;

uint32_t reverse_bits(uint32_t x) {
    x = __builtin_bswap32(x);  // GCC and Clang
    x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);
    x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);
    x = ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);
    return x;
}

// Owen scramble of a bit-reversed value: each output bit is its input bit
// flipped by a hash of the less significant bits only (multiplications and
// additions carry upwards), i.e. of the more significant bits before reversal.
// The scramble of x is reverse_bits(owen_hash_reversed(reverse_bits(x), seed)).
uint32_t owen_hash_reversed(uint32_t x, uint32_t seed) {
    x ^= x * 0x3d20adeau;
    x += seed;
    x *= (seed >> 16) | 1u;
    x ^= x * 0x05526c56u;
    x ^= x * 0x53a22864u;
    return x;
}

// A Sobol' dimension from its primitive polynomial (degree, coefficients a)
// and initial direction integers m (Joe & Kuo's notation). Stored bit-reversed,
// as the XOR of the direction numbers selected by each byte of the index: the
// scramble below works on reversed bits.
struct SobolDimension {
    uint32_t by_byte[4][256];
};

constexpr SobolDimension make_dimension(int degree, uint32_t a, const uint32_t (&m_initial)[4]) {
    uint32_t m[32] = {};
    for (int k = 0; k < degree; ++k) m[k] = m_initial[k];
    for (int k = degree; k < 32; ++k) {
        m[k] = m[k - degree] ^ (m[k - degree] << degree);
        for (int j = 1; j < degree; ++j)
            if ((a >> (degree - 1 - j)) & 1u) m[k] ^= m[k - j] << j;
    }
    SobolDimension t{};
    for (int b = 0; b < 4; ++b)
        for (int v = 0; v < 256; ++v)
            for (int bit = 0; bit < 8; ++bit)
                if (v & (1 << bit)) {
                    // direction number k = m_k / 2^(k+1), as 32 fraction bits, reversed
                    const int k = 8 * b + bit;
                    const uint32_t direction = m[k] << (31 - k);
                    uint32_t reversed = 0;
                    for (int i = 0; i < 32; ++i) reversed |= ((direction >> i) & 1u) << (31 - i);
                    t.by_byte[b][v] ^= reversed;
                }
    return t;
}

constexpr SobolDimension kDimension1 = make_dimension(1, 0, {1});        // x + 1
constexpr SobolDimension kDimension2 = make_dimension(2, 1, {1, 3});     // x^2 + x + 1
constexpr SobolDimension kDimension3 = make_dimension(3, 1, {1, 3, 1});  // x^3 + x + 1
constexpr SobolDimension kDimension5 = make_dimension(4, 1, {1, 1, 3, 3});   // x^4 + x + 1 (Joe & Kuo d = 6)
constexpr SobolDimension kDimension6 = make_dimension(4, 4, {1, 3, 5, 13});  // x^4 + x^3 + 1 (Joe & Kuo d = 7)

// Point `index` of a dimension, bit-reversed.
uint32_t sobol_reversed(const SobolDimension& d, uint32_t index) {
    return d.by_byte[0][index & 0xffu] ^ d.by_byte[1][(index >> 8) & 0xffu] ^ d.by_byte[2][(index >> 16) & 0xffu] ^
           d.by_byte[3][index >> 24];
}

// The top 24 bits as a float in [0, 1), exactly.
float unit_float(uint32_t bits) { return float(bits >> 8) * 0x1p-24f; }

uint32_t scrambled(uint32_t reversed_value, uint32_t seed) {
    return reverse_bits(owen_hash_reversed(reversed_value, seed));
}

}  // namespace

void fill_sobol(uint64_t seed, uint64_t pixel_index, int spp, bool scrambled_points, Point2f* film, Point2f* lens,
                float* time, float* wavelength, bool time_from_index) {
    if (!scrambled_points) {  // dimensions 0-1 for both, unscrambled: the raw sequence, for tests
        for (int i = 0; i < spp; ++i) {
            film[i] = lens[i] = {unit_float(reverse_bits(uint32_t(i))),
                                 unit_float(reverse_bits(sobol_reversed(kDimension1, uint32_t(i))))};
            if (time) time[i] = unit_float(reverse_bits(sobol_reversed(kDimension6, uint32_t(i))));
            if (wavelength) wavelength[i] = unit_float(reverse_bits(sobol_reversed(kDimension5, uint32_t(i))));
        }
        return;
    }
    // Independent 32-bit seeds per pixel and per dimension. Dimension 0 is the
    // index reversed, so reversed it is the index itself. The time seed is
    // drawn after the others, so film and lens are the same with or without it.
    Pcg32 rng(seed, pixel_index, kSobolStream);
    const uint32_t seeds[4] = {rng.next_u32(), rng.next_u32(), rng.next_u32(), rng.next_u32()};
    for (int i = 0; i < spp; ++i) {
        const uint32_t index = uint32_t(i);
        film[i] = {unit_float(scrambled(index, seeds[0])),
                   unit_float(scrambled(sobol_reversed(kDimension1, index), seeds[1]))};
        lens[i] = {unit_float(scrambled(sobol_reversed(kDimension2, index), seeds[2])),
                   unit_float(scrambled(sobol_reversed(kDimension3, index), seeds[3]))};
    }
    // The time seed, then the wavelength seed: each drawn whether or not it is
    // used, so that neither changes the other's points.
    const uint32_t time_seed = rng.next_u32(), wavelength_seed = rng.next_u32();
    if (time && time_from_index)  // i / spp, as 32 fraction bits, bit-reversed
        for (int i = 0; i < spp; ++i)
            time[i] = unit_float(scrambled(reverse_bits(uint32_t((uint64_t(i) << 32) / uint64_t(spp))), time_seed));
    else if (time)
        for (int i = 0; i < spp; ++i)
            time[i] = unit_float(scrambled(sobol_reversed(kDimension6, uint32_t(i)), time_seed));
    if (wavelength)
        for (int i = 0; i < spp; ++i)
            wavelength[i] = unit_float(scrambled(sobol_reversed(kDimension5, uint32_t(i)), wavelength_seed));
}

void fill_sobol_padded(uint64_t seed, uint64_t pixel_index, int spp, Point2f* film, Point2f* lens, float* time) {
    // Each group from the best-stratified dimensions alone (0-1, or 0),
    // scrambled with its own seeds, then the lens and time points shuffled.
    Pcg32 rng(seed, pixel_index, kSobolPaddedStream);
    uint32_t seeds[5];
    for (uint32_t& s : seeds) s = rng.next_u32();
    for (int i = 0; i < spp; ++i) {
        const uint32_t index = uint32_t(i), d1 = sobol_reversed(kDimension1, index);
        film[i] = {unit_float(scrambled(index, seeds[0])), unit_float(scrambled(d1, seeds[1]))};
        lens[i] = {unit_float(scrambled(index, seeds[2])), unit_float(scrambled(d1, seeds[3]))};
        if (time) time[i] = unit_float(scrambled(index, seeds[4]));
    }
    for (int i = spp - 1; i > 0; --i) std::swap(lens[i], lens[rng.next_below(uint32_t(i + 1))]);
    if (time)
        for (int i = spp - 1; i > 0; --i) std::swap(time[i], time[rng.next_below(uint32_t(i + 1))]);
}

}  // namespace lc
