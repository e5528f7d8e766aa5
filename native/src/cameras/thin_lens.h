// Thin lens (Cook et al. 1984; paper section 2.2): a point on the lens
// aperture (a disk, or an N-blade polygon of the same area: aperture.h),
// aimed through the film point's image on the plane of focus.
#pragma once

#include <algorithm>
#include <vector>

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
    // Spectral renders of a lens with dispersion: 1 / (plane of focus at λ), 1/m,
    // every nm from 380 nm, from the lens's focal length at λ with the film
    // where it is (lenscompare/render_spectral.py); empty: no dispersion.
    std::vector<double> inverse_focus_per_m_by_nm;

    bool disperses() const { return !inverse_focus_per_m_by_nm.empty(); }

    MaybeRay generate_ray(Point2f raster_px, Point2f lens_sample) const {
        return generate_ray_focused(raster_px, lens_sample, 1.0 / focus_distance_m);
    }

    // The ray at wavelength nm: a thin lens of focal length f(λ) keeps the
    // chief ray through its centre, so only the plane of focus moves.
    MaybeRay generate_ray_at(Point2f raster_px, Point2f lens_sample, float nm) const {
        if (!disperses()) return generate_ray(raster_px, lens_sample);
        return generate_ray_focused(raster_px, lens_sample, inverse_focus_per_m_at(nm));
    }

    // 1 / (plane of focus at nm), 1/m (linear between whole nm); needs disperses().
    double inverse_focus_per_m_at(float nm) const {
        const double x = std::clamp(double(nm) - 380.0, 0.0, double(inverse_focus_per_m_by_nm.size() - 1));
        const size_t i = std::min(size_t(x), inverse_focus_per_m_by_nm.size() - 2);
        const double t = x - double(i);
        return inverse_focus_per_m_by_nm[i] * (1.0 - t) + inverse_focus_per_m_by_nm[i + 1] * t;
    }

    void generate_rays_at(Point2f raster_px, Point2f lens_sample, const float* nm, int n, MaybeRay* out) const {
        for (int k = 0; k < n; ++k) out[k] = generate_ray_at(raster_px, lens_sample, nm[k]);
    }

    MaybeRay generate_ray_focused(Point2f raster_px, Point2f lens_sample, double inverse_focus_per_m) const {
        // Sample point on lens
        double ax, ay;
        aperture.sample(lens_sample, disk_mapping, &ax, &ay);
        Vec3d p_lens{lens_radius_m * ax, lens_radius_m * ay, 0.0};
        // Ray from the lens point through the film point's image on the plane of
        // focus, film.direction * focus_distance; written divided by the focus
        // distance (normalize does not mind the scale), so that any finite focus
        // distance, 1e300 m too, stays finite.
        Vec3d dir_camera = normalize(film.direction(raster_px) - p_lens * inverse_focus_per_m);
        return CameraRay{world_from_camera.world_from_camera_point(p_lens),
                         world_from_camera.world_from_camera_vector(dir_camera), 1.0f};
    }
};

}  // namespace lc
