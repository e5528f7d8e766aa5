// Pinhole camera (camera obscura): every ray passes through the centre of
// projection. It shares the film distance of the thin lens focused at the same
// distance, so pinhole and thin-lens frames match (DESIGN.md).
#pragma once

#include "cameras/camera_ray.h"

namespace lc {

struct PinholeCamera {
    Frame world_from_camera;
    FilmToScreen film;

    MaybeRay generate_ray(Point2f raster_px, Point2f /*lens_sample*/) const {
        Vec3d dir_camera = normalize(film.direction(raster_px));
        return CameraRay{world_from_camera.origin, world_from_camera.world_from_camera_vector(dir_camera), 1.0f};
    }
};

}  // namespace lc
