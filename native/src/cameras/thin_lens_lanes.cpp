#include "cameras/thin_lens_lanes.h"

#include <cmath>

namespace lc {

// target_clones: GCC builds the loop once per instruction set and the library
// picks one when it loads; IEEE square roots and divisions round alike in
// every width, so every clone gives the same rays.
__attribute__((target_clones("default", "avx2", "avx512f"))) void thin_lens_rays_lanes(
    int n, const double* screen_x, const double* screen_y, const double* lens_x_m, const double* lens_y_m,
    double inverse_focus_per_m, const Frame& f, double* const origin_m[3], double* const direction[3]) {
    const Vec3d o = f.origin, r = f.right, u = f.up, w = f.forward;
    // The rows never overlap; unsaid, GCC wanted 39 run-time alias checks
    // (its limit is 10) and left the loop scalar (5 % of a thin lens render).
#pragma GCC ivdep
    for (int i = 0; i < n; ++i) {
        const double lx = lens_x_m[i], ly = lens_y_m[i];
        // film.direction(raster) - p_lens * inverse_focus, p_lens = (lx, ly, 0)
        const double dx = screen_x[i] - lx * inverse_focus_per_m;
        const double dy = screen_y[i] - ly * inverse_focus_per_m;
        const double dz = 1.0 - 0.0 * inverse_focus_per_m;
        const double length = std::sqrt(dx * dx + dy * dy + dz * dz);
        const double ux = dx / length, uy = dy / length, uz = dz / length;
        // world_from_camera_point(p_lens) and world_from_camera_vector(unit), as vec.h sums them
        origin_m[0][i] = o.x + r.x * lx + u.x * ly + w.x * 0.0;
        origin_m[1][i] = o.y + r.y * lx + u.y * ly + w.y * 0.0;
        origin_m[2][i] = o.z + r.z * lx + u.z * ly + w.z * 0.0;
        direction[0][i] = r.x * ux + u.x * uy + w.x * uz;
        direction[1][i] = r.y * ux + u.y * uy + w.y * uz;
        direction[2][i] = r.z * ux + u.z * uy + w.z * uz;
    }
}

__attribute__((target_clones("default", "avx2", "avx512f"))) void screen_points_lanes(int n, const FilmToScreen& film,
                                                                                    const Point2f* raster_px,
                                                                                    double* screen_x,
                                                                                    double* screen_y) {
    const double width_px = film.width_px, height_px = film.height_px;
    const double half_width = film.screen_half_width, half_height = film.screen_half_height;
#pragma GCC ivdep
    for (int i = 0; i < n; ++i) {
        // film.direction, operation for operation
        screen_x[i] = (2.0 * double(raster_px[i].x) / width_px - 1.0) * half_width;
        screen_y[i] = (1.0 - 2.0 * double(raster_px[i].y) / height_px) * half_height;
    }
}

__attribute__((target_clones("default", "avx2", "avx512f"))) void concentric_disk_lanes(int n,
                                                                                      const Point2f* lens_sample,
                                                                                      double* disk_x, double* disk_y) {
#pragma GCC ivdep
    for (int i = 0; i < n; ++i) concentric_disk(lens_sample[i], &disk_x[i], &disk_y[i]);
}

}  // namespace lc
