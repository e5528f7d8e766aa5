// Test and benchmark hooks for the lens-system camera (lenscompare._native.diagnostics):
// pass-rate statistics, lens-only throughput and the brute-force pupil reference.
// The render never calls these.
#pragma once

#include <cstddef>
#include <cstdint>

#include "cameras/lens_system.h"

namespace lc {

// Traced and passed counts for given samples (pass-rate statistics).
struct LensPassCounts {
    uint64_t samples = 0, traced = 0, passed = 0;
};
LensPassCounts count_lens_passes(const LensSystemCamera& camera, const Point2f* raster_px, const Point2f* lens,
                                 size_t n);

// Lens-only throughput: n random (film, pupil) samples traced through the
// lens on `threads` threads, no scene. Returns the seconds taken.
double measure_lens_throughput(const LensSystemCamera& camera, uint64_t n, int threads, LensPassCounts* counts);

// The same camera aiming at the brute-force pupil (ExitPupil::brute_force),
// calibrated anew: the reference the tight pupil sampler is tested against.
LensSystemCamera with_brute_force_pupil(const LensSystemCamera& camera);

}  // namespace lc
