#include "diagnostics/lens_passes.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <memory>

#include "rng.h"

namespace lc {

LensPassCounts count_lens_passes(const LensSystemCamera& camera, const Point2f* raster_px, const Point2f* lens,
                                 size_t n) {
    LensPassCounts counts;
    for (size_t i = 0; i < n; ++i) {
        ++counts.samples;
        LensRay ray;
        double area;
        if (!camera.sample_lens_ray(raster_px[i], lens[i], &ray, &area)) continue;
        ++counts.traced;
        if (trace_from_film(camera.elements, &ray)) ++counts.passed;
    }
    return counts;
}

double measure_lens_throughput(const LensSystemCamera& camera, uint64_t n, int threads, LensPassCounts* counts) {
    constexpr uint64_t kChunk = 4096;
    std::atomic<uint64_t> traced{0}, passed{0};
    auto start = std::chrono::steady_clock::now();
    tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<uint64_t>(0, (n + kChunk - 1) / kChunk), [&](const auto& chunks) {
            uint64_t local_traced = 0, local_passed = 0;
            for (uint64_t chunk = chunks.begin(); chunk < chunks.end(); ++chunk) {
                Pcg32 rng(0, chunk);
                uint64_t end = std::min(n, (chunk + 1) * kChunk);
                for (uint64_t first = chunk * kChunk; first < end; first += kLensBatch) {
                    // Sample a batch of film and pupil points, then trace them in lockstep
                    Point2f raster[kLensBatch], u[kLensBatch];
                    for (int i = 0; i < kLensBatch; ++i) {
                        raster[i] = {rng.next_float() * camera.width_px, rng.next_float() * camera.height_px};
                        u[i] = {rng.next_float(), rng.next_float()};
                    }
                    LensRayBatch batch;
                    double area_mm2[kLensBatch];
                    camera.sample_batch(raster, u, int(std::min<uint64_t>(kLensBatch, end - first)), &batch,
                                        area_mm2);
                    for (int i = 0; i < kLensBatch; ++i) local_traced += batch.alive[i];
                    trace_from_film_batch(camera.elements, &batch, camera.trace_kernel);
                    for (int i = 0; i < kLensBatch; ++i) local_passed += batch.alive[i];
                }
            }
            traced += local_traced;
            passed += local_passed;
        });
    });
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    counts->samples = n;
    counts->traced = traced.load();
    counts->passed = passed.load();
    return seconds;
}

LensSystemCamera with_brute_force_pupil(const LensSystemCamera& camera) {
    auto pupil = std::make_shared<const ExitPupil>(
        ExitPupil::brute_force(camera.elements, film_corner_radius_mm(camera.film_width_mm, camera.film_height_mm)));
    // Built afresh, not copied, so that the members derived from the pupil follow it.
    LensSystemCamera brute{camera.world_from_camera, camera.elements,       camera.film_z_mm,
                           camera.entrance_pupil_z_mm, camera.film_width_mm, camera.film_height_mm,
                           camera.width_px,          camera.height_px,      std::move(pupil)};
    brute.trace_kernel = camera.trace_kernel;
    calibrate_centre_irradiance(&brute);
    return brute;
}

}  // namespace lc
