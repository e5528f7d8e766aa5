#include "depth.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace lc {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Depth along the view axis of the first hit through raster point (x, y).
float depth_at(const Scene& scene, const PinholeCamera& camera, float x, float y) {
    const Vec3d dir_camera = normalize(camera.film.direction({x, y}));
    const Vec3d dir_world = camera.world_from_camera.world_from_camera_vector(dir_camera);
    const float t = scene.first_hit_distance(Vec3f(camera.world_from_camera.origin), Vec3f(dir_world));
    // Along the ray -> along the view axis: t cos(angle to the axis).
    return std::isinf(t) ? kInf : float(double(t) * dir_camera.z);
}

bool jumps(float a, float b) {
    if (std::isinf(a) || std::isinf(b)) return std::isinf(a) != std::isinf(b);
    return std::fabs(double(a) - double(b)) > kDepthEdgeJump * std::min(double(a), double(b));
}

}  // namespace

void render_depth(const Scene& scene, const PinholeCamera& camera, int threads, float* depth_m,
                  const uint8_t* refine) {
    const int width = camera.film.width_px, height = camera.film.height_px;
    std::vector<float> centre(size_t(width) * size_t(height));
    tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
    arena.execute([&] {
        // The pixel centres. Not a mean over film samples: a mean would invent,
        // at every silhouette, a depth between two surfaces that neither has.
        tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
            for (int y = rows.begin(); y < rows.end(); ++y)
                for (int x = 0; x < width; ++x)
                    centre[size_t(y) * size_t(width) + size_t(x)] = depth_at(scene, camera, x + 0.5f, y + 0.5f);
        });
        // Silhouettes: the nearest surface in the pixel, whose rim the pixel's colour holds.
        tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
            for (int y = rows.begin(); y < rows.end(); ++y)
                for (int x = 0; x < width; ++x) {
                    const size_t p = size_t(y) * size_t(width) + size_t(x);
                    float depth = centre[p];
                    // 8-neighbours: an object may cover only a pixel's corner.
                    bool edge = refine != nullptr && refine[p] != 0;
                    for (int dy = -1; dy <= 1 && !edge; ++dy)
                        for (int dx = -1; dx <= 1 && !edge; ++dx) {
                            const int nx = x + dx, ny = y + dy;
                            if (nx >= 0 && nx < width && ny >= 0 && ny < height)
                                edge = jumps(depth, centre[size_t(ny) * size_t(width) + size_t(nx)]);
                        }
                    if (edge)
                        for (int j = 0; j < kDepthEdgeGrid; ++j)
                            for (int i = 0; i < kDepthEdgeGrid; ++i)
                                depth = std::min(depth, depth_at(scene, camera, x + (i + 0.5f) / kDepthEdgeGrid,
                                                                 y + (j + 0.5f) / kDepthEdgeGrid));
                    depth_m[p] = depth;
                }
        });
    });
}

}  // namespace lc
