#include "depth.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <limits>

namespace lc {

void render_depth(const Scene& scene, const PinholeCamera& camera, int threads, float* depth_m) {
    const int width = camera.film.width_px, height = camera.film.height_px;
    tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
            for (int y = rows.begin(); y < rows.end(); ++y)
                for (int x = 0; x < width; ++x) {
                    // The pixel centre only: a mean over film samples would invent a
                    // depth between two surfaces at every silhouette.
                    const Vec3d dir_camera = normalize(camera.film.direction({float(x) + 0.5f, float(y) + 0.5f}));
                    const Vec3d dir_world = camera.world_from_camera.world_from_camera_vector(dir_camera);
                    const float t = scene.first_hit_distance(Vec3f(camera.world_from_camera.origin), Vec3f(dir_world));
                    // Along the ray -> along the view axis: t cos(angle to the axis).
                    depth_m[size_t(y) * size_t(width) + size_t(x)] =
                        std::isinf(t) ? std::numeric_limits<float>::infinity() : float(double(t) * dir_camera.z);
                }
        });
    });
}

}  // namespace lc
