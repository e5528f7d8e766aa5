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
        // Compute point on plane of focus (the chief ray's hit, z = focus distance)
        Vec3d p_focus = film.direction(raster_px) * focus_distance_m;
        // Ray from the lens point through the focus point
        Vec3d dir_camera = normalize(p_focus - p_lens);
        return CameraRay{world_from_camera.world_from_camera_point(p_lens),
                         world_from_camera.world_from_camera_vector(dir_camera), 1.0f};
    }
};

}  // namespace lc
