#include "samplers.h"

#include <cmath>
#include <utility>

#include "rng.h"

namespace lc {
namespace {

// Stream dimensions: independent random streams per pixel for each use.
constexpr uint64_t kFilmStream = 0;
constexpr uint64_t kLensStream = 1;
constexpr uint64_t kShuffleStream = 2;

void fill_random(Pcg32& rng, int spp, Point2f* out) {
    for (int i = 0; i < spp; ++i) out[i] = {rng.next_float(), rng.next_float()};
}

void fill_jittered(Pcg32& rng, int spp, Point2f* out) {
    int nx, ny;
    jittered_strata(spp, &nx, &ny);
    for (int iy = 0; iy < ny; ++iy)
        for (int ix = 0; ix < nx; ++ix) {
            // (ix + u) / nx stays below 1 because u <= 1 - 2^-24.
            float x = (float(ix) + rng.next_float()) / float(nx);
            float y = (float(iy) + rng.next_float()) / float(ny);
            out[iy * nx + ix] = {std::fmin(x, 0x1.fffffep-1f), std::fmin(y, 0x1.fffffep-1f)};
        }
}

// Random permutation so that film stratum i is not always paired with lens
// stratum i (which would correlate the two 2-D dimensions).
void shuffle(Pcg32& rng, int n, Point2f* points) {
    for (int i = n - 1; i > 0; --i) std::swap(points[i], points[rng.next_below(uint32_t(i + 1))]);
}

}  // namespace

void jittered_strata(int spp, int* nx, int* ny) {
    int best = 1;
    for (int d = 1; d * d <= spp; ++d)
        if (spp % d == 0) best = d;
    *ny = best;
    *nx = spp / best;
}

void fill_pixel_samples(SamplerKind kind, uint64_t seed, uint64_t pixel_index, int spp,
                        Point2f* film, Point2f* lens) {
    Pcg32 film_rng(seed, pixel_index, kFilmStream);
    Pcg32 lens_rng(seed, pixel_index, kLensStream);
    switch (kind) {
        case SamplerKind::Random:
            fill_random(film_rng, spp, film);
            fill_random(lens_rng, spp, lens);
            break;
        case SamplerKind::Jittered: {
            fill_jittered(film_rng, spp, film);
            fill_jittered(lens_rng, spp, lens);
            Pcg32 shuffle_rng(seed, pixel_index, kShuffleStream);
            shuffle(shuffle_rng, spp, lens);
            break;
        }
    }
}

Point2f map_to_disk(Point2f u, DiskMapping mapping) {
    constexpr float kPi = 3.14159265358979323846f;
    if (mapping == DiskMapping::Polar) {
        // r = sqrt(u) makes the density uniform in area.
        float r = std::sqrt(u.x);
        float phi = 2.0f * kPi * u.y;
        return {r * std::cos(phi), r * std::sin(phi)};
    }
    // Shirley & Chiu 1997 concentric mapping: squares to circles, keeps strata compact.
    float ox = 2.0f * u.x - 1.0f, oy = 2.0f * u.y - 1.0f;
    if (ox == 0.0f && oy == 0.0f) return {0.0f, 0.0f};
    float r, theta;
    if (std::fabs(ox) > std::fabs(oy)) {
        r = ox;
        theta = (kPi / 4.0f) * (oy / ox);
    } else {
        r = oy;
        theta = (kPi / 2.0f) - (kPi / 4.0f) * (ox / oy);
    }
    return {r * std::cos(theta), r * std::sin(theta)};
}

}  // namespace lc
