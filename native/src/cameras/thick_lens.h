// Thick lens (paper section 2.3): rays from the film reach the rear principal
// plane H', are translated parallel to the axis to the front principal plane
// H, and leave as from a thin lens of the same focal length.
//
// camera.position is H (DESIGN.md) and focus_distance is measured from H, so
// the translation changes neither the ray's height nor its direction in front
// of H: in object space the thick lens is the thin lens at H. The gap moves
// the film and the lens body (film to object = d + gap + d'), which is what
// lens layouts and the lens-system comparison see; no ray does, so the gap
// stays on the Python side (lenscompare/cameras/thick.py).
#pragma once

#include "cameras/thin_lens.h"

namespace lc {

struct ThickLensCamera {
    ThinLensCamera at_front_principal_plane;  // origin at H

    MaybeRay generate_ray(Point2f raster_px, Point2f lens_sample) const {
        // Point on H' and its translation to H share (x, y): the ray leaving H
        // is the thin-lens ray through the same lens sample.
        return at_front_principal_plane.generate_ray(raster_px, lens_sample);
    }

    void generate_ray_batch(const Point2f* raster_px, const Point2f* lens_sample, int n,
                            CameraRayBatch* out) const {
        at_front_principal_plane.generate_ray_batch(raster_px, lens_sample, n, out);
    }
    void generate_ray_rows(const Point2f* raster_px, const Point2f* lens_sample, int n, CameraRayRows* out) const {
        at_front_principal_plane.generate_ray_rows(raster_px, lens_sample, n, out);
    }
    // Its rays are the thin lens's at H: so is their pencil (camera_pencil.h).
    bool pencil(double x0_px, double y0_px, double x1_px, double y1_px, CameraPencil* out) const {
        return at_front_principal_plane.pencil(x0_px, y0_px, x1_px, y1_px, out);
    }

    // Spectral renders: the thin lens at H with the focal length at λ (H itself stays put).
    bool disperses() const { return at_front_principal_plane.disperses(); }
    MaybeRay generate_ray_at(Point2f raster_px, Point2f lens_sample, float nm) const {
        return at_front_principal_plane.generate_ray_at(raster_px, lens_sample, nm);
    }
    void generate_rays_at(Point2f raster_px, Point2f lens_sample, const float* nm, int n, MaybeRay* out) const {
        at_front_principal_plane.generate_rays_at(raster_px, lens_sample, nm, n, out);
    }
    void generate_rays_sharing(Point2f raster_px, Point2f lens_sample, const float* nm, MaybeRay* out,
                               bool* shares) const {
        at_front_principal_plane.generate_rays_sharing(raster_px, lens_sample, nm, out, shares);
    }
    bool carries_bands() const { return at_front_principal_plane.carries_bands(); }
    bool band_roulette() const { return at_front_principal_plane.band_roulette(); }
    const DispersionRuns& band_runs() const { return at_front_principal_plane.band_runs(); }
    const std::vector<double>& band_focus_table() const { return at_front_principal_plane.band_focus_table(); }
    bool band_rays(const Point2f* raster_px, const Point2f* lens_sample, int n, BandRays* out,
                   const LensPencilCheck* check = nullptr) const {
        return at_front_principal_plane.band_rays(raster_px, lens_sample, n, out, check);
    }
    void whole_ray_rows(const BandRays& rays, CameraRayRows* out, BandRayWeights* weights) const {
        at_front_principal_plane.whole_ray_rows(rays, out, weights);
    }
    void band_ray_rows(const BandRays& rays, int first, int n, CameraRayRows* out, BandRayWeights* weights) const {
        at_front_principal_plane.band_ray_rows(rays, first, n, out, weights);
    }
    void generate_shared_ray_rows(const Point2f* raster_px, const Point2f* lens_sample, const HeroWavelengths* w,
                                  int n, CameraRayRows* rows, bool (*own)[kCameraBatch]) const {
        at_front_principal_plane.generate_shared_ray_rows(raster_px, lens_sample, w, n, rows, own);
    }
};

}  // namespace lc
