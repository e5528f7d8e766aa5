// Benchmark hook for the lens-system camera (lenscompare._native.diagnostics):
// the CPU time of each stage of its rays, and of the pinhole's rays, so that
// bench/bench_lens_ceiling.py can say how much of a pinhole sample the lens
// camera alone costs. The render never calls this.
#pragma once

#include <cstddef>

#include "cameras/lens_system.h"
#include "cameras/pinhole.h"

namespace lc {

// This thread's CPU seconds for samples [0, n) in the render loop's batches,
// a few dozen batches at a time so that they stay in cache as a tile's do:
// sample (film points, exit-pupil picks and aiming: sample_batch), trace (the
// batch trace through the elements, on the aimed rays), whole (the render's
// own float rows, generate_weighted_ray_rows: sample, trace and the step to
// the world; from the ray table where the camera has one) and pinhole (the
// pinhole's rows, generate_ray_rows, the same samples).
struct LensStageSeconds {
    double sample = 0.0, trace = 0.0, whole = 0.0, pinhole = 0.0;
};
LensStageSeconds lens_stage_seconds(const LensSystemCamera& camera, const PinholeCamera& pinhole,
                                    const Point2f* raster_px, const Point2f* lens, size_t n);

}  // namespace lc
