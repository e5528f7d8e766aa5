// Thin lens (Cook et al. 1984; paper section 2.2): a point on the lens
// aperture (a disk, or an N-blade polygon of the same area: aperture.h),
// aimed through the film point's image on the plane of focus.
#pragma once

#include "aperture.h"
#include "cameras/camera_ray.h"
#include "samplers.h"

namespace lc {

struct ThinLensCamera {
    Frame world_from_camera;  // origin at the lens centre
    FilmToScreen film;        // from the film distance d' = f d / (d - f)
    double lens_radius_m;     // f / (2 N): the circle's, whatever the aperture's shape
    double focus_distance_m;  // along the view axis
    DiskMapping disk_mapping;
    ApertureShape aperture = ApertureShape::circle();

    MaybeRay generate_ray(Point2f raster_px, Point2f lens_sample) const {
        // Sample point on lens
        double ax, ay;
        aperture.sample(lens_sample, disk_mapping, &ax, &ay);
        Vec3d p_lens{lens_radius_m * ax, lens_radius_m * ay, 0.0};
        // Ray from the lens point through the film point's image on the plane of
        // focus, film.direction * focus_distance; written divided by the focus
        // distance (normalize does not mind the scale), so that any finite focus
        // distance, 1e300 m too, stays finite.
        Vec3d dir_camera = normalize(film.direction(raster_px) - p_lens * (1.0 / focus_distance_m));
        return CameraRay{world_from_camera.world_from_camera_point(p_lens),
                         world_from_camera.world_from_camera_vector(dir_camera), 1.0f};
    }
};

}  // namespace lc
