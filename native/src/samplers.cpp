#include "samplers.h"

#include <cmath>
#include <numeric>
#include <utility>
#include <vector>
#include <algorithm>
#include <type_traits>

#include "cpu_kernels.h"
#include "rng.h"

namespace lc {
namespace {

// Stream dimensions: independent random streams per pixel for each use.
constexpr uint64_t kFilmStream = 0;
constexpr uint64_t kLensStream = 1;  // (2 was the lens strata's shuffle, now hashed from this stream)
constexpr uint64_t kTimeStream = 3;  // the time samples' own stream: drawing them changes no film or lens point
constexpr uint64_t kWavelengthStream = 4;  // the same for wavelengths

// A thread's scratch for the samplers, reached once per pixel: each
// thread_local of a shared library is a call to __tls_get_addr (with one per
// buffer, 2 % of an empty scene's thin-lens render under callgrind).
struct Scratch {
    std::vector<uint32_t> bits;       // draw_u32's numbers
    std::vector<float> corners;       // stratum_corners', made for size() / 2 points
    std::vector<float> lens_flat;     // fill_jittered_paired's points before their pairing,
    std::vector<uint32_t> to_sample;  // and the pairing
    std::vector<Point2f> unused_lens; // the lens points a pinhole does not ask for
};

Scratch& thread_scratch() {
    thread_local Scratch scratch;
    return scratch;
}

// rng's next n outputs, drawn by Pcg32::fill_u32 (several states at a time,
// not one chain of multiplications) into the scratch, valid until the next
// call: fill_random's and jitter_strata's random numbers.
const uint32_t* draw_u32(Pcg32& rng, int n, Scratch& scratch) {
    scratch.bits.resize(size_t(n));
    rng.fill_u32(scratch.bits.data(), n);
    return scratch.bits.data();
}

// The same numbers in the same order as next_float twice per point.
void fill_random(Pcg32& rng, int spp, Scratch& scratch, Point2f* out) {
    const uint32_t* bits = draw_u32(rng, 2 * spp, scratch);
    for (int i = 0; i < spp; ++i) out[i] = {Pcg32::to_float(bits[2 * i]), Pcg32::to_float(bits[2 * i + 1])};
}

// The corners of point i's stratum (row by row: column i mod nx, row i / nx)
// as floats, x and y side by side, made once per spp and thread, so that the
// jitter below is one flat loop: over a row of nx points (8 at 64 spp) GCC's
// vectors were mostly empty.
const float* stratum_corners(int spp, int nx, Scratch& scratch) {
    if (scratch.corners.size() != size_t(2 * spp)) {  // nx follows from spp
        scratch.corners.resize(size_t(2 * spp));
        for (int i = 0; i < spp; ++i)
            scratch.corners[size_t(2 * i)] = float(i % nx), scratch.corners[size_t(2 * i + 1)] = float(i / nx);
    }
    return scratch.corners.data();
}

// One jittered point per stratum, point i in stratum i (row by row), as x
// and y side by side in out[0, 2 spp): the random numbers first, then the
// arithmetic in SIMD lanes (built per instruction set: the divisions run 16
// wide on AVX-512 and round as the baseline's do), the same numbers in the
// same order as next_float per coordinate.
LC_BUILT_PER_ISA void jitter_strata(Pcg32& rng, int spp, Scratch& scratch, float* out) {
    int nx, ny;
    jittered_strata(spp, &nx, &ny);
    const float* corner = stratum_corners(spp, nx, scratch);
    const uint32_t* bits = draw_u32(rng, 2 * spp, scratch);
    const float x_strata = float(nx), y_strata = float(ny);
    for (int k = 0; k < 2 * spp; ++k) {
        // (corner + u) / strata stays below 1 because u <= 1 - 2^-24, but for its rounding.
        const float strata = (k & 1) ? y_strata : x_strata;
        out[k] = below_one((corner[k] + Pcg32::to_float(bits[k])) / strata);
    }
}

// Point2f is two floats side by side: an array of them is 2 n floats.
static_assert(std::is_standard_layout_v<Point2f> && sizeof(Point2f) == 2 * sizeof(float));
float* as_floats(Point2f* points) { return &points->x; }

void fill_jittered(Pcg32& rng, int spp, Scratch& scratch, Point2f* out) {
    jitter_strata(rng, spp, scratch, as_floats(out));
}

// Kensler's hashed permutation ("Correlated Multi-Jittered Sampling", Pixar
// technical memo 13-01, 2013), the form of pbrt-v4's PermutationElement: each
// step is invertible on the low bits that mask w keeps, so i -> hash is a
// permutation of [0, w + 1) chosen by p.
[[gnu::always_inline]] inline uint32_t kensler_hash(uint32_t i, uint32_t w, uint32_t p) {
    i ^= p;
    i *= 0xe170893du;
    i ^= p >> 16;
    i ^= (i & w) >> 4;
    i ^= p >> 8;
    i *= 0x0929eb3fu;
    i ^= p >> 23;
    i ^= (i & w) >> 1;
    i *= 1u | p >> 27;
    i *= 0x6935fa69u;
    i ^= (i & w) >> 11;
    i *= 0x74dcb303u;
    i ^= (i & w) >> 2;
    i *= 0x9e501cc3u;
    i ^= (i & w) >> 2;
    i *= 0xc860a3dfu;
    i &= w;
    i ^= i >> 5;
    return i;
}

// The permutation of [0, n) that p picks: kensler_hash on the next power of
// two, walked until it falls below n (cycle walking keeps it a bijection),
// then turned by p mod n. A power-of-two n needs no walk, and its loop runs
// in SIMD lanes.
LC_BUILT_PER_ISA void hashed_permutation(int n, uint32_t p, uint32_t* out) {
    uint32_t w = uint32_t(n - 1);
    w |= w >> 1, w |= w >> 2, w |= w >> 4, w |= w >> 8, w |= w >> 16;
    if ((uint32_t(n) & uint32_t(n - 1)) == 0) {
        for (int i = 0; i < n; ++i) out[i] = (kensler_hash(uint32_t(i), w, p) + p) & w;
        return;
    }
    // Sixteen indices walk side by side, each lane hashed again while it is
    // outside [0, n): the same walk per index as one at a time (the same
    // permutation), in SIMD, without the walk's unpredictable branch. One
    // index at a time it was 9 % of peers_lit's thin-lens render at 48 spp
    // (61 instructions a sample under callgrind, a branch missed every
    // 2.4 samples). Lanes past n start inside and stay: a walk from an
    // index >= n need not end, since its cycle may hold no index below n.
    const uint32_t count = uint32_t(n), turn = p % count;
    constexpr int kLanes = 16;
    for (int first = 0; first < n; first += kLanes) {
        uint32_t j[kLanes];
        for (int k = 0; k < kLanes; ++k) {
            const uint32_t i = uint32_t(first + k);
            j[k] = i < count ? kensler_hash(i, w, p) : 0u;
        }
        for (;;) {
            uint32_t outside = 0;
            for (int k = 0; k < kLanes; ++k) outside |= uint32_t(j[k] >= count);
            if (outside == 0) break;
            for (int k = 0; k < kLanes; ++k) j[k] = j[k] >= count ? kensler_hash(j[k], w, p) : j[k];
        }
        const int end = std::min(kLanes, n - first);
        for (int k = 0; k < end; ++k) {
            const uint32_t turned = j[k] + turn;
            out[first + k] = turned >= count ? turned - count : turned;
        }
    }
}

// The lens strata paired with the film's at random: lens point j (stratum j)
// goes to sample permutation(j), so that film stratum i is not always paired
// with lens stratum i (which would correlate the two 2-D dimensions). The
// permutation is hashed from one more number of the lens stream; it was a
// Fisher-Yates shuffle, whose chain of dependent swaps through memory was a
// tenth of an empty scene's thin-lens render (perf).
void fill_jittered_paired(Pcg32& rng, int spp, Scratch& scratch, Point2f* out) {
    scratch.lens_flat.resize(size_t(2 * spp)), scratch.to_sample.resize(size_t(spp));
    const float* flat = scratch.lens_flat.data();
    const uint32_t* to_sample = scratch.to_sample.data();
    jitter_strata(rng, spp, scratch, scratch.lens_flat.data());
    hashed_permutation(spp, rng.next_u32(), scratch.to_sample.data());
    for (int j = 0; j < spp; ++j) out[to_sample[j]] = {flat[2 * j], flat[2 * j + 1]};
}

// The multiplier coprime to n nearest n / golden ratio: i -> a * i mod n is
// then a permutation of 0..n-1 that keeps neighbours far apart.
int golden_multiplier(int n) {
    int a0 = int(std::lround(0.6180339887498949 * n));
    for (int d = 0; d <= n; ++d) {
        if (a0 + d <= n && std::gcd(a0 + d, n) == 1) return a0 + d;
        if (a0 - d >= 1 && std::gcd(a0 - d, n) == 1) return a0 - d;
    }
    return 1;
}

// Film: the centres of the nx x ny strata, row by row. Lens: the same centres,
// film cell (ix, iy) paired with lens cell
//     jx = (a * ix + iy) mod nx,   jy = (iy + jx) mod ny,
// two shears of the grid torus (so a bijection) with a = golden_multiplier(nx).
// Every film column then meets ny different lens columns and every film row
// all ny lens rows; measured |correlation| between any film and any
// lens coordinate is below 3 / sqrt(spp) for all spp from 16 to 1024. Simpler
// orders fail: a stride i -> i * p mod spp ties each lens column to one film
// column, bit reversal ties lens x to film y (correlation 0.57 at 64 spp).
void fill_regular(int spp, Point2f* film, Point2f* lens) {
    int nx, ny;
    jittered_strata(spp, &nx, &ny);
    int a = golden_multiplier(nx);
    auto centre = [&](int ix, int iy) {
        return Point2f{(float(ix) + 0.5f) / float(nx), (float(iy) + 0.5f) / float(ny)};
    };
    for (int iy = 0; iy < ny; ++iy)
        for (int ix = 0; ix < nx; ++ix) {
            int jx = int((int64_t(a) * ix + iy) % nx);
            int jy = (iy + jx) % ny;
            film[iy * nx + ix] = centre(ix, iy);
            lens[iy * nx + ix] = centre(jx, jy);
        }
}

// Time for the non-sobol samplers: one uniform point in each of the spp
// intervals [k/spp, (k+1)/spp), in random order (random: independent points).
// Wavelengths use the same construction on their own stream (and, for
// regular, the lattice's coordinates swapped, so that the ranks differ from time's).
void fill_time(SamplerKind kind, uint64_t seed, uint64_t pixel_index, int spp, float* time,
               uint64_t stream = kTimeStream) {
    if (kind == SamplerKind::Regular) {
        // The interval centres, film cell (ix, iy) taking the rank of
        // frac(ix / p + iy / p^2 + 1/2), p the plastic number (Roberts' R2
        // lattice): measured |correlation| between time and any film or lens
        // coordinate is below 3 / sqrt(spp) for all but 5 spp from 16 to 1024
        // (strided orders i -> a i mod spp reach 0.99 at 64 spp).
        constexpr double kPlastic = 1.324717957244746;
        int nx, ny;
        jittered_strata(spp, &nx, &ny);
        std::vector<double> key(static_cast<size_t>(spp));
        std::vector<int> order(static_cast<size_t>(spp));
        for (int i = 0; i < spp; ++i) {
            const double a = double(i % nx), b = double(i / nx);
            const double v = stream == kTimeStream ? a / kPlastic + b / (kPlastic * kPlastic) + 0.5
                                                   : b / kPlastic + a / (kPlastic * kPlastic) + 0.25;
            key[size_t(i)] = v - std::floor(v);
            order[size_t(i)] = i;
        }
        std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return key[size_t(a)] < key[size_t(b)]; });
        for (int rank = 0; rank < spp; ++rank) time[order[size_t(rank)]] = (float(rank) + 0.5f) / float(spp);
        return;
    }
    Pcg32 rng(seed, pixel_index, stream);
    if (kind == SamplerKind::Random) {
        for (int i = 0; i < spp; ++i) time[i] = rng.next_float();
        return;
    }
    for (int k = 0; k < spp; ++k) time[k] = below_one((float(k) + rng.next_float()) / float(spp));
    for (int i = spp - 1; i > 0; --i) std::swap(time[i], time[rng.next_below(uint32_t(i + 1))]);
}

}  // namespace

void jittered_strata(int spp, int* nx, int* ny) {
    // The largest divisor d with d * d <= spp, searched downward from the
    // square root: one division at a square spp, where the upward search's
    // divisions were an eighth of fill_jittered's time (perf).
    int best = std::max(int(std::sqrt(double(spp))), 1);
    while (best > 1 && best * best > spp) --best;  // the square root's rounding, either way
    while ((best + 1) * (best + 1) <= spp) ++best;
    while (best > 1 && spp % best != 0) --best;
    *ny = best;
    *nx = spp / best;
}

void fill_pixel_samples(SamplerKind kind, uint64_t seed, uint64_t pixel_index, int spp,
                        Point2f* film, Point2f* lens, float* time, float* wavelength) {
    if (spp <= 0) return;
    Scratch& scratch = thread_scratch();
    // No lens points asked for (a pinhole): random and jittered draw them from
    // streams of their own, so they skip them and the rest is unchanged; the
    // other samplers make them with the film's and they go to scratch.
    if (lens == nullptr && kind != SamplerKind::Random && kind != SamplerKind::Jittered) {
        scratch.unused_lens.resize(size_t(spp));
        lens = scratch.unused_lens.data();
    }
    switch (kind) {
        case SamplerKind::Random: {
            Pcg32 film_rng(seed, pixel_index, kFilmStream), lens_rng(seed, pixel_index, kLensStream);
            fill_random(film_rng, spp, scratch, film);
            if (lens) fill_random(lens_rng, spp, scratch, lens);
            break;
        }
        case SamplerKind::Jittered: {
            Pcg32 film_rng(seed, pixel_index, kFilmStream), lens_rng(seed, pixel_index, kLensStream);
            fill_jittered(film_rng, spp, scratch, film);
            if (lens == nullptr) break;
            fill_jittered_paired(lens_rng, spp, scratch, lens);
            break;
        }
        case SamplerKind::Regular:
            fill_regular(spp, film, lens);
            break;
        case SamplerKind::Poisson:
            fill_poisson(seed, pixel_index, spp, film, lens);
            break;
        case SamplerKind::Sobol:
            fill_sobol(seed, pixel_index, spp, true, film, lens, time, wavelength);
            return;  // time and wavelength from the same net
        case SamplerKind::SobolUnscrambled:
            fill_sobol(seed, pixel_index, spp, false, film, lens, time, wavelength);
            return;
        case SamplerKind::SobolTimeNet:
            fill_sobol(seed, pixel_index, spp, true, film, lens, time, wavelength, true);
            return;
        case SamplerKind::SobolPadded:
            fill_sobol_padded(seed, pixel_index, spp, film, lens, time);
            if (wavelength) fill_time(SamplerKind::Jittered, seed, pixel_index, spp, wavelength, kWavelengthStream);
            return;
    }
    if (time) fill_time(kind, seed, pixel_index, spp, time);
    if (wavelength) fill_time(kind, seed, pixel_index, spp, wavelength, kWavelengthStream);
}

SamplerKind pass_sampler(SamplerKind kind, int first_sample) {
    return kind == SamplerKind::Sobol && first_sample == 0 ? SamplerKind::SobolTimeNet : kind;
}

PolarDiskPoint map_to_disk_polar(Point2f u, DiskMapping mapping) {
    constexpr float kPi = 3.14159265358979323846f;
    if (mapping == DiskMapping::Polar) {
        // r = sqrt(u) makes the density uniform in area.
        return {std::sqrt(u.x), 2.0f * kPi * u.y};
    }
    // Shirley & Chiu 1997 concentric mapping: squares to circles, keeps strata compact.
    float ox = 2.0f * u.x - 1.0f, oy = 2.0f * u.y - 1.0f;
    if (ox == 0.0f && oy == 0.0f) return {0.0f, 0.0f};
    if (std::fabs(ox) > std::fabs(oy)) return {ox, (kPi / 4.0f) * (oy / ox)};
    return {oy, (kPi / 2.0f) - (kPi / 4.0f) * (ox / oy)};
}

Point2f map_to_disk(Point2f u, DiskMapping mapping) {
    if (mapping == DiskMapping::Concentric) {
        double x, y;
        concentric_disk(u, &x, &y);
        return {float(x), float(y)};
    }
    PolarDiskPoint p = map_to_disk_polar(u, mapping);
    return {p.r * std::cos(p.theta), p.r * std::sin(p.theta)};
}

}  // namespace lc
