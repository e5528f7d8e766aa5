#include "diagnostics/lens_stages.h"

#include <time.h>

#include <algorithm>
#include <array>

namespace lc {

namespace {

double thread_cpu_seconds() {
    timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// Batches per chunk: 48 aimed batches (75 KB) stay in L2 between the stages.
constexpr size_t kChunkBatches = 48;

}  // namespace

LensStageSeconds lens_stage_seconds(const LensSystemCamera& camera, const PinholeCamera& pinhole,
                                    const Point2f* raster_px, const Point2f* lens, size_t n) {
    const size_t batches = (n + kCameraBatch - 1) / kCameraBatch;
    auto count = [&](size_t b) { return int(std::min<size_t>(kCameraBatch, n - b * kCameraBatch)); };
    std::array<LensRayBatch, kChunkBatches> aimed;
    std::array<double, kChunkBatches * kLensBatch> area_mm2;
    CameraRayRows rows;
    float weight[kCameraBatch];
    bool alive[kCameraBatch];
    LensStageSeconds s;
    for (size_t first = 0; first < batches; first += kChunkBatches) {
        const size_t last = std::min(batches, first + kChunkBatches);
        double start = thread_cpu_seconds();
        for (size_t b = first; b < last; ++b)
            camera.sample_batch(raster_px + b * kCameraBatch, lens + b * kCameraBatch, count(b), &aimed[b - first],
                                &area_mm2[(b - first) * kLensBatch]);
        double end = thread_cpu_seconds();
        s.sample += end - start;
        start = end;
        for (size_t b = first; b < last; ++b)
            trace_from_film_batch(camera.elements, &aimed[b - first], camera.trace_kernel, camera.trace_precision);
        end = thread_cpu_seconds();
        s.trace += end - start;
        start = end;
        for (size_t b = first; b < last; ++b)
            camera.generate_weighted_ray_rows(raster_px + b * kCameraBatch, lens + b * kCameraBatch, count(b), &rows,
                                              weight, alive, nullptr);
        end = thread_cpu_seconds();
        s.whole += end - start;
        start = end;
        for (size_t b = first; b < last; ++b)
            pinhole.generate_ray_rows(raster_px + b * kCameraBatch, lens + b * kCameraBatch, count(b), &rows);
        s.pinhole += thread_cpu_seconds() - start;
    }
    return s;
}

}  // namespace lc
