// What the render loop is asked to do (RenderSettings) and what it reports
// (RenderStats), apart from the loop so that its stages can read them too.
#pragma once

#include <algorithm>
#include <cstdint>

#include "samplers.h"

namespace lc {

struct RenderSettings {
    int width_px = 0, height_px = 0;
    int spp = 1;
    SamplerKind sampler = SamplerKind::Jittered;
    uint64_t seed = 0;
    int threads = 0;  // 0: all cores
    // Per-pixel sample counts (adaptive sampling): pixel p, row-major over the
    // whole image, takes samples [min(first_sample, end), end) of its own
    // sequence of end = sample_end[p] samples, and its output is their mean
    // (0 for none). nullptr: samples [0, spp) everywhere.
    const uint32_t* sample_end = nullptr;
    int first_sample = 0;
    // Optional output, one per pixel like the image: the variance of each
    // pixel's mean, summed over R, G and B (0 below two samples).
    float* variance_of_mean = nullptr;

    // The samples [first, end) pixel p takes.
    struct SampleRange {
        int first, end;
    };
    SampleRange samples_of(uint64_t pixel_index) const {
        if (!sample_end) return {0, spp};
        const int end = int(sample_end[pixel_index]);
        return {std::min(first_sample, end), end};
    }
};

struct RenderStats {
    uint64_t samples = 0;      // camera samples drawn
    uint64_t rays_passed = 0;  // samples that became a ray (not vignetted)
};

}  // namespace lc
