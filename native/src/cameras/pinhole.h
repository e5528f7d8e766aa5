// Pinhole camera (camera obscura): every ray passes through the centre of
// projection. It shares the film distance of the thin lens focused at the same
// distance, so pinhole and thin-lens frames match (DESIGN.md).
#pragma once

#include "cameras/camera_pencil.h"
#include "cameras/camera_ray.h"
#include "cameras/thin_lens_lanes.h"

namespace lc {

struct PinholeCamera {
    Frame world_from_camera;
    FilmToScreen film;
    // Its rays ignore the lens sample, so the render loop draws none (render_tile.h).
    static constexpr bool kUsesLensSamples = false;

    MaybeRay generate_ray(Point2f raster_px, Point2f /*lens_sample*/) const {
        Vec3d dir_camera = normalize(film.direction(raster_px));
        return CameraRay{world_from_camera.origin, world_from_camera.world_from_camera_vector(dir_camera), 1.0f};
    }

    // Its rays through raster rectangle [x0, x1] x [y0, y1] (camera_pencil.h): one point, no lens.
    bool pencil(double x0_px, double y0_px, double x1_px, double y1_px, CameraPencil* out) const {
        *out = pencil_of(world_from_camera, film, 0.0, 0.0, x0_px, y0_px, x1_px, y1_px);
        return true;
    }

    // A batch of n <= kCameraBatch samples (render_tile.h), side by side: the
    // thin lens's lanes with every lens point at the centre, in single
    // precision (generate_ray's directions to float rounding; the origin
    // rounded once). One at a time, the ray's three divisions and square root
    // left the core waiting (12 % of a pinhole render under perf).
    void generate_ray_rows(const Point2f* raster_px, const Point2f* /*lens_sample*/, int n,
                           CameraRayRows* out) const {
        float screen_x[kCameraBatch], screen_y[kCameraBatch];
        const float centre[kCameraBatch] = {};
        screen_points_lanes(n, film, raster_px, screen_x, screen_y);
        thin_lens_rays_lanes(n, screen_x, screen_y, centre, centre, 0.0, FrameF::of(world_from_camera), out);
        const Vec3d& o = world_from_camera.origin;  // the centre rounded once, as generate_ray_batch's
        for (int i = 0; i < n; ++i)
            out->origin[0][i] = float(o.x), out->origin[1][i] = float(o.y), out->origin[2][i] = float(o.z);
    }

    // generate_ray_rows' rays in double, the origin exactly.
    void generate_ray_batch(const Point2f* raster_px, const Point2f* lens_sample, int n,
                            CameraRayBatch* out) const {
        CameraRayRows rows;
        generate_ray_rows(raster_px, lens_sample, n, &rows);
        widen_rows(rows, n, out);
        const Vec3d& o = world_from_camera.origin;
        for (int i = 0; i < n; ++i) out->origin[0][i] = o.x, out->origin[1][i] = o.y, out->origin[2][i] = o.z;
    }
};

}  // namespace lc
