#include "diagnostics/raw_throughput.h"

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>
#include <cmath>

#include "render.h"
#include "rng.h"

namespace lc {

RawThroughput measure_raw_primary_throughput(const Scene& scene, const PinholeCamera& camera, int spp, int threads) {
    const int width = camera.film.width_px, height = camera.film.height_px;
    std::atomic<uint64_t> hits{0};
    auto start = std::chrono::steady_clock::now();
    tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
    arena.execute([&] {
        tbb::blocked_range2d<int> rows_cols(0, height, kTileSize, 0, width, kTileSize);
        tbb::parallel_for(rows_cols, [&](const tbb::blocked_range2d<int>& tile) {
            uint64_t tile_hits = 0;
            for (int y = tile.rows().begin(); y < tile.rows().end(); ++y)
                for (int x = tile.cols().begin(); x < tile.cols().end(); ++x) {
                    Pcg32 rng(0, uint64_t(y) * uint64_t(width) + uint64_t(x));
                    for (int i = 0; i < spp; ++i) {
                        Point2f raster_px{float(x) + rng.next_float(), float(y) + rng.next_float()};
                        Vec3d d = camera.world_from_camera.world_from_camera_vector(normalize(camera.film.direction(raster_px)));
                        tile_hits += std::isfinite(scene.first_hit_distance(Vec3f(camera.world_from_camera.origin), Vec3f(d)));
                    }
                }
            hits += tile_hits;
        });
    });
    auto stop = std::chrono::steady_clock::now();
    RawThroughput result;
    result.seconds = std::chrono::duration<double>(stop - start).count();
    result.rays = uint64_t(width) * uint64_t(height) * uint64_t(spp);
    result.hits = hits.load();
    return result;
}

}  // namespace lc
