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
// the thin lens, bit for bit (its double generate_ray, its single-precision batch).
// In a spectral render two more parts make it a camera that disperses
// (render_tile_spectral.h: disperses(), generate_rays_at):
//   - lateral colour: the distortion table once per wavelength (a few rows,
//     read linearly in wavelength too), so that each wavelength's ray looks
//     along that wavelength's chief ray;
//   - longitudinal colour: the thin lens's plane of focus per wavelength
//     (ThinLensCamera::inverse_focus_per_m_by_nm), as the thin lens model.
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
    // Lateral colour: screen_scale at each of color_nm (increasing; empty: none).
    std::vector<double> color_nm;
    std::vector<RadialTable> screen_scale_by_color;

    bool disperses() const { return !color_nm.empty() || lens.disperses(); }

    bool is_thin_lens() const { return screen_scale.empty() && illumination.empty() && std::isinf(max_radius_mm); }

    MaybeRay generate_ray(Point2f raster_px, Point2f lens_sample) const {
        if (is_thin_lens()) return lens.generate_ray(raster_px, lens_sample);  // the thin lens, bit for bit
        FilmSample film;
        if (!film_sample(raster_px, lens_sample, &film)) return std::nullopt;
        const double k = screen_scale.empty() ? 1.0 : screen_scale.at(film.r_mm);
        return ray_through(film, k, 1.0 / lens.focus_distance_m);
    }

    // The render loop's batch: without tables the thin lens's (single
    // precision, as ray_through), otherwise ray by ray.
    void generate_ray_batch(const Point2f* raster_px, const Point2f* lens_sample, int n,
                            CameraRayBatch* out) const {
        if (is_thin_lens()) return lens.generate_ray_batch(raster_px, lens_sample, n, out);
        for (int i = 0; i < n; ++i) {
            const MaybeRay ray = generate_ray(raster_px[i], lens_sample[i]);
            out->alive[i] = bool(ray);
            if (!ray) continue;
            out->origin[0][i] = ray->origin.x, out->origin[1][i] = ray->origin.y, out->origin[2][i] = ray->origin.z;
            out->direction[0][i] = ray->direction.x, out->direction[1][i] = ray->direction.y;
            out->direction[2][i] = ray->direction.z, out->weight[i] = ray->weight;
        }
    }

    // The ray at wavelength nm: its screen point scaled by that wavelength's
    // chief-ray table, its plane of focus that wavelength's.
    MaybeRay generate_ray_at(Point2f raster_px, Point2f lens_sample, float nm) const {
        MaybeRay ray;
        generate_rays_at(raster_px, lens_sample, &nm, 1, &ray);
        return ray;
    }

    // One film and lens sample, rays at n wavelengths: the sample's radius,
    // weight and pupil point are shared, only the table row and focus differ.
    void generate_rays_at(Point2f raster_px, Point2f lens_sample, const float* nm, int n, MaybeRay* out) const {
        FilmSample film;
        if (!film_sample(raster_px, lens_sample, &film)) {
            for (int k = 0; k < n; ++k) out[k] = std::nullopt;
            return;
        }
        for (int k = 0; k < n; ++k) {
            const double scale = !color_nm.empty() ? scale_at(nm[k], film.r_mm)
                                 : screen_scale.empty() ? 1.0 : screen_scale.at(film.r_mm);
            const double inverse_focus = lens.disperses() ? lens.inverse_focus_per_m_at(nm[k])
                                                          : 1.0 / lens.focus_distance_m;
            out[k] = ray_through(film, scale, inverse_focus);
        }
    }

  private:
    // In single precision, as the thin lens's batch (thin_lens_lanes.h), so
    // that without tables the composite's rays are the thin lens's.
    struct FilmSample {
        float screen_x, screen_y;  // paraxial screen point (tangents, z = 1)
        float lens_x_m, lens_y_m;  // point on the entrance pupil
        double r_mm;               // film radius
        float weight;              // relative illumination
    };

    // False when the sample lies outside the image circle or gets no light.
    bool film_sample(Point2f raster_px, Point2f lens_sample, FilmSample* out) const {
        // Film radius of the sample, mm (the film centre is the raster centre)
        const FilmToScreen& film = lens.film;
        const double x_mm = (double(raster_px.x) / film.width_px - 0.5) * film_width_mm;
        const double y_mm = (double(raster_px.y) / film.height_px - 0.5) * film_height_mm;
        out->r_mm = std::sqrt(x_mm * x_mm + y_mm * y_mm);
        if (!(out->r_mm <= max_radius_mm)) return false;  // outside the image circle: black
        out->weight = illumination.empty() ? 1.0f : float(illumination.at(out->r_mm));
        if (!(out->weight > 0.0f)) return false;
        film.screen_point(raster_px, &out->screen_x, &out->screen_y);
        double ax, ay;
        lens.aperture.sample(lens_sample, lens.disk_mapping, &ax, &ay);
        out->lens_x_m = float(ax * lens.lens_radius_m), out->lens_y_m = float(ay * lens.lens_radius_m);
        return true;
    }

    // Lateral colour's screen scale at (nm, r): linear between rows, clamped at the ends.
    double scale_at(float nm, double r_mm) const {
        const size_t last = color_nm.size() - 1;
        if (!(double(nm) > color_nm[0])) return screen_scale_by_color[0].at(r_mm);
        if (!(double(nm) < color_nm[last])) return screen_scale_by_color[last].at(r_mm);
        size_t i = 0;
        while (color_nm[i + 1] <= double(nm)) ++i;  // a handful of rows
        const double t = (double(nm) - color_nm[i]) / (color_nm[i + 1] - color_nm[i]);
        return screen_scale_by_color[i].at(r_mm) * (1.0 - t) + screen_scale_by_color[i + 1].at(r_mm) * t;
    }

    // The screen point pushed out or in by scale, the pupil point aimed through
    // its image on the plane of focus (thin_lens_ray, as the thin lens).
    MaybeRay ray_through(const FilmSample& film, double scale, double inverse_focus_per_m) const {
        const float screen_x = float(double(film.screen_x) * scale), screen_y = float(double(film.screen_y) * scale);
        float o[3], d[3];
        thin_lens_ray(screen_x, screen_y, film.lens_x_m, film.lens_y_m, float(inverse_focus_per_m),
                      FrameF::of(lens.world_from_camera), o, d);
        return CameraRay{{o[0], o[1], o[2]}, {d[0], d[1], d[2]}, film.weight};
    }
};

}  // namespace lc
