// Composite camera (issue 14, "effects as parts"): a thin lens at the entrance
// pupil of a lens system (radius 0: a pinhole) with the lens system's paraxial
// image scale, plus two optional radial tables traced once through the
// prescription (lenscompare/lenses/maps.py):
//   - distortion: the screen direction of a film point at radius r is scaled
//     so that it looks along the real chief ray that lands at r;
//   - vignetting: the ray weight is the relative illumination RI(r).
// Both tables are sampled evenly over film radii [0, max_radius_mm] and read
// with linear interpolation; beyond max_radius_mm (the image circle, or where
// the chief ray fails) no ray leaves. With both tables empty the composite is
// the thin lens, bit for bit.
#pragma once

#include <cmath>
#include <vector>

#include "cameras/camera_ray.h"
#include "cameras/thin_lens.h"

namespace lc {

// Values at evenly spaced film radii 0, step, 2 step, ... (mm); empty: no table.
struct RadialTable {
    std::vector<double> values;
    double radius_step_mm = 1.0;

    bool empty() const { return values.empty(); }

    // Linear interpolation; the last value beyond the end.
    double at(double radius_mm) const {
        const double t = radius_mm / radius_step_mm;
        const size_t last = values.size() - 1;
        if (!(t < double(last))) return values[last];
        const size_t i = size_t(t);
        const double f = t - double(i);
        return values[i] + f * (values[i + 1] - values[i]);
    }
};

struct CompositeCamera {
    ThinLensCamera lens;         // at the entrance pupil; its film maps with the paraxial image scale
    double film_width_mm, film_height_mm;
    RadialTable screen_scale;    // distortion: real chief-ray tangent over the paraxial one (1 on the axis)
    RadialTable illumination;    // vignetting: RI(r), 1 on the axis
    double max_radius_mm;        // film radius beyond which nothing gets through (infinity: none)

    MaybeRay generate_ray(Point2f raster_px, Point2f lens_sample) const {
        if (screen_scale.empty() && illumination.empty() && std::isinf(max_radius_mm))
            return lens.generate_ray(raster_px, lens_sample);  // the thin lens, bit for bit
        // Film radius of the sample, mm (the film centre is the raster centre)
        const FilmToScreen& film = lens.film;
        const double x_mm = (double(raster_px.x) / film.width_px - 0.5) * film_width_mm;
        const double y_mm = (double(raster_px.y) / film.height_px - 0.5) * film_height_mm;
        const double r_mm = std::sqrt(x_mm * x_mm + y_mm * y_mm);
        if (!(r_mm <= max_radius_mm)) return std::nullopt;  // outside the image circle: black
        const float weight = illumination.empty() ? 1.0f : float(illumination.at(r_mm));
        if (!(weight > 0.0f)) return std::nullopt;
        // Screen point (paraxial tangent), pushed out or in to the real chief ray's
        Vec3d screen = film.direction(raster_px);
        if (!screen_scale.empty()) {
            const double k = screen_scale.at(r_mm);
            screen.x *= k, screen.y *= k;
        }
        // Sample point on the entrance pupil, aimed through the screen point's
        // image on the plane of focus (as ThinLensCamera, divided by the distance)
        double ax, ay;
        lens.aperture.sample(lens_sample, lens.disk_mapping, &ax, &ay);
        Vec3d p_lens{lens.lens_radius_m * ax, lens.lens_radius_m * ay, 0.0};
        Vec3d dir_camera = normalize(screen - p_lens * (1.0 / lens.focus_distance_m));
        const Frame& frame = lens.world_from_camera;
        return CameraRay{frame.world_from_camera_point(p_lens), frame.world_from_camera_vector(dir_camera), weight};
    }
};

}  // namespace lc
