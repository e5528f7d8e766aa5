#include "cameras/thin_lens_lanes.h"

#include <algorithm>
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

__attribute__((target_clones("default", "avx2", "avx512f"))) void thin_lens_rays_lanes_focused(
    int n, const float* screen_x, const float* screen_y, const float* lens_x_m, const float* lens_y_m,
    const float* inverse_focus_per_m, const FrameF& f, CameraRayRows* out) {
#pragma GCC ivdep
    for (int i = 0; i < n; ++i) {
        float o[3], d[3];
        thin_lens_ray(screen_x[i], screen_y[i], lens_x_m[i], lens_y_m[i], inverse_focus_per_m[i], f, o, d);
        for (int k = 0; k < 3; ++k) out->origin[k][i] = o[k], out->direction[k][i] = d[k];
    }
}

__attribute__((target_clones("default", "avx2", "avx512f"))) void inverse_focus_lanes(
    int n, const std::vector<double>& inverse_focus_per_m_by_nm, const float* nm, double* inverse_focus_per_m) {
    const double* table = inverse_focus_per_m_by_nm.data();
    const int size = int(inverse_focus_per_m_by_nm.size());
    for (int i = 0; i < n; ++i) {
        const double x = std::clamp(double(nm[i]) - 380.0, 0.0, double(size - 1));
        // int, not size_t: AVX2 converts doubles to 32-bit integers only (the same j)
        const int j = std::min(int(x), size - 2);
        const double t = x - double(j);
        inverse_focus_per_m[i] = table[j] * (1.0 - t) + table[j + 1] * t;
    }
}

__attribute__((target_clones("default", "avx2", "avx512f"))) void shifted_film_points_lanes(
    int n, const Point2f* raster_px, const double* lens_x_m, const double* lens_y_m, const double* shift_per_m,
    double x_scale, double y_scale, bool* stays, Point2f* wrapped_px) {
    for (int i = 0; i < n; ++i) {
        const double pixel_x = std::floor(double(raster_px[i].x)), pixel_y = std::floor(double(raster_px[i].y));
        // Screen x grows with raster x, screen y against raster y (FilmToScreen).
        const double x = double(raster_px[i].x) + lens_x_m[i] * shift_per_m[i] * x_scale;
        const double y = double(raster_px[i].y) - lens_y_m[i] * shift_per_m[i] * y_scale;
        const double floor_x = std::floor(x), floor_y = std::floor(y);
        stays[i] = floor_x == pixel_x && floor_y == pixel_y;
        wrapped_px[i] = {float(pixel_x + (x - floor_x)), float(pixel_y + (y - floor_y))};
    }
}

__attribute__((target_clones("default", "avx2", "avx512f"))) void screen_points_lanes(int n, const FilmToScreen& film,
                                                                                    const Point2f* raster_px,
                                                                                    float* screen_x, float* screen_y) {
    const FilmToScreen local = film;  // a copy the stores below cannot touch: its terms leave the loop
#pragma GCC ivdep
    for (int i = 0; i < n; ++i) local.screen_point(raster_px[i], &screen_x[i], &screen_y[i]);
}

__attribute__((target_clones("default", "avx2", "avx512f"))) void concentric_disk_lanes_double(
    int n, const Point2f* lens_sample, double radius_m, double* disk_x_m, double* disk_y_m) {
#pragma GCC ivdep
    for (int i = 0; i < n; ++i) {
        double x, y;
        concentric_disk(lens_sample[i], &x, &y);
        disk_x_m[i] = radius_m * x, disk_y_m[i] = radius_m * y;
    }
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
