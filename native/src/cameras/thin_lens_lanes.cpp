#include "cameras/thin_lens_lanes.h"

#include <cmath>

namespace lc {

// target_clones: GCC builds the loop once per instruction set and the library
// picks one when it loads; IEEE square roots and divisions round alike in
// every width, so every clone gives the same rays.
__attribute__((target_clones("default", "avx2", "avx512f"))) void thin_lens_rays_lanes(
    int n, const float* screen_x, const float* screen_y, const float* lens_x_m, const float* lens_y_m,
    double inverse_focus_per_m, const FrameF& f, CameraRayRows* out) {
    const float inverse_focus = float(inverse_focus_per_m);
    // The rows never overlap; unsaid, GCC wanted run-time alias checks past
    // its limit and left the loop scalar.
#pragma GCC ivdep
    for (int i = 0; i < n; ++i) {
        float o[3], d[3];
        thin_lens_ray(screen_x[i], screen_y[i], lens_x_m[i], lens_y_m[i], inverse_focus, f, o, d);
        for (int k = 0; k < 3; ++k) out->origin[k][i] = o[k], out->direction[k][i] = d[k];
    }
}

__attribute__((target_clones("default", "avx2", "avx512f"))) void screen_points_lanes(int n, const FilmToScreen& film,
                                                                                    const Point2f* raster_px,
                                                                                    float* screen_x, float* screen_y) {
    const FilmToScreen local = film;  // a copy the stores below cannot touch: its terms leave the loop
#pragma GCC ivdep
    for (int i = 0; i < n; ++i) local.screen_point(raster_px[i], &screen_x[i], &screen_y[i]);
}

__attribute__((target_clones("default", "avx2", "avx512f"))) void concentric_disk_lanes(int n,
                                                                                      const Point2f* lens_sample,
                                                                                      double radius_m,
                                                                                      float* disk_x_m,
                                                                                      float* disk_y_m) {
#pragma GCC ivdep
    for (int i = 0; i < n; ++i) {
        double x, y;
        concentric_disk(lens_sample[i], &x, &y);
        disk_x_m[i] = float(x * radius_m), disk_y_m[i] = float(y * radius_m);
    }
}

}  // namespace lc
