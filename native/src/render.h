// The render loop, written once and instantiated per camera model: per pixel,
// the sampler fills the pixel's film and lens samples, the camera turns each
// into a ray (or nothing, when vignetted), the scene returns radiance.
// Every pixel owns its random stream, so the image is the same for any thread
// count and any tiling.
#pragma once

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <type_traits>
#include <utility>
#include <cstdint>
#include <vector>

#include "cameras/camera_ray.h"
#include "samplers.h"
#include "scene.h"

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

constexpr int kTileSize = 16;

// Cameras that can turn several samples into rays at once (the lens system
// traces them in lockstep) say so with generate_rays(raster, lens, n, out).
template <class Camera, class = void>
struct GeneratesBatches : std::false_type {};
template <class Camera>
struct GeneratesBatches<Camera, std::void_t<decltype(std::declval<const Camera&>().generate_rays(
                                    nullptr, nullptr, 0, static_cast<MaybeRay*>(nullptr)))>> : std::true_type {};

// Rays for n <= kCameraBatch samples.
template <class Camera>
void camera_rays(const Camera& camera, const Point2f* raster_px, const Point2f* lens, int n, MaybeRay* out) {
    if constexpr (GeneratesBatches<Camera>::value) {
        camera.generate_rays(raster_px, lens, n, out);
    } else {
        for (int i = 0; i < n; ++i) out[i] = camera.generate_ray(raster_px[i], lens[i]);
    }
}

// Renders rows [row_begin, row_end) into rgb (height x width x 3, row 0 at the top).
template <class Camera>
RenderStats render_rows(const Scene& scene, const Camera& camera, const RenderSettings& s, int row_begin,
                        int row_end, float* rgb) {
    std::atomic<uint64_t> rays_passed{0}, samples_drawn{0};
    tbb::task_arena arena(s.threads > 0 ? s.threads : tbb::task_arena::automatic);
    arena.execute([&] {
        tbb::blocked_range2d<int> rows_cols(row_begin, row_end, kTileSize, 0, s.width_px, kTileSize);
        tbb::parallel_for(rows_cols, [&](const tbb::blocked_range2d<int>& tile) {
            std::vector<Point2f> film(size_t(s.spp)), lens(size_t(s.spp));
            const int tile_w = tile.cols().size();
            // Double accumulation per pixel of the tile: 1024 spp of float radiance would lose bits.
            std::vector<double> sums(size_t(tile_w) * size_t(tile.rows().size()) * 3, 0.0);
            std::vector<double> squares(s.variance_of_mean ? sums.size() : 0, 0.0);
            uint64_t tile_passed = 0, tile_samples = 0;
            // Camera samples are gathered across the tile's pixels into
            // batches of kCameraBatch, and the rays packed into 8-wide Embree
            // packets, so that low sample counts still fill both. Each
            // pixel's samples are still summed in sample order.
            RayBatch batch;
            float weight[kPacketSize];
            size_t slot[kPacketSize];
            auto flush = [&] {
                if (batch.count == 0) return;
                Vec3f radiance[kPacketSize];
                scene.radiance(batch, radiance);
                for (int j = 0; j < batch.count; ++j) {
                    double* sum = &sums[3 * slot[j]];
                    const double r = double(radiance[j].x) * weight[j], g = double(radiance[j].y) * weight[j],
                                 b = double(radiance[j].z) * weight[j];
                    sum[0] += r, sum[1] += g, sum[2] += b;
                    if (!squares.empty()) {
                        double* square = &squares[3 * slot[j]];
                        square[0] += r * r, square[1] += g * g, square[2] += b * b;
                    }
                }
                tile_passed += uint64_t(batch.count);
                batch.count = 0;
            };
            Point2f pending_raster[kCameraBatch], pending_lens[kCameraBatch];
            size_t pending_slot[kCameraBatch];
            int pending = 0;
            auto trace_pending = [&] {
                MaybeRay rays[kCameraBatch];
                camera_rays(camera, pending_raster, pending_lens, pending, rays);
                for (int i = 0; i < pending; ++i) {
                    if (!rays[i]) continue;  // vignetted: contributes nothing
                    batch.origin[batch.count] = Vec3f(rays[i]->origin);
                    batch.direction[batch.count] = Vec3f(rays[i]->direction);
                    weight[batch.count] = rays[i]->weight;
                    slot[batch.count++] = pending_slot[i];
                    if (batch.count == kPacketSize) flush();
                }
                pending = 0;
            };
            for (int y = tile.rows().begin(); y < tile.rows().end(); ++y) {
                for (int x = tile.cols().begin(); x < tile.cols().end(); ++x) {
                    uint64_t pixel_index = uint64_t(y) * uint64_t(s.width_px) + uint64_t(x);
                    size_t local = size_t(y - tile.rows().begin()) * size_t(tile_w) + size_t(x - tile.cols().begin());
                    const auto [first, end] = s.samples_of(pixel_index);
                    if (end == first) continue;
                    if (film.size() < size_t(end)) film.resize(size_t(end)), lens.resize(size_t(end));
                    fill_pixel_samples(s.sampler, s.seed, pixel_index, end, film.data(), lens.data());
                    tile_samples += uint64_t(end - first);
                    for (int i = first; i < end; ++i) {
                        pending_raster[pending] = {float(x) + film[size_t(i)].x, float(y) + film[size_t(i)].y};
                        pending_lens[pending] = lens[size_t(i)];
                        pending_slot[pending++] = local;
                        if (pending == kCameraBatch) trace_pending();
                    }
                }
            }
            trace_pending();
            flush();
            for (int y = tile.rows().begin(); y < tile.rows().end(); ++y)
                for (int x = tile.cols().begin(); x < tile.cols().end(); ++x) {
                    size_t local = size_t(y - tile.rows().begin()) * size_t(tile_w) + size_t(x - tile.cols().begin());
                    const uint64_t pixel_index = uint64_t(y) * uint64_t(s.width_px) + uint64_t(x);
                    const auto [first, end] = s.samples_of(pixel_index);
                    const int count = end - first;
                    float* out = rgb + 3 * pixel_index;
                    double variance = 0.0;
                    for (int c = 0; c < 3; ++c) {
                        const double mean = count > 0 ? sums[3 * local + size_t(c)] / count : 0.0;
                        out[c] = float(mean);
                        if (!squares.empty() && count > 1)
                            variance += std::max(squares[3 * local + size_t(c)] / count - mean * mean, 0.0) /
                                        (count - 1);
                    }
                    if (s.variance_of_mean) s.variance_of_mean[pixel_index] = float(variance);
                }
            rays_passed += tile_passed;
            samples_drawn += tile_samples;
        });
    });
    RenderStats stats;
    stats.samples = samples_drawn.load();
    stats.rays_passed = rays_passed.load();
    return stats;
}

}  // namespace lc
