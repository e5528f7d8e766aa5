// The lens system's camera rays through a film tile, bounded as a pencil
// (camera_pencil.h), so that its tiles skip the own primitives no ray of
// theirs can meet, as the thin lens's and the pinhole's do.
//
// Unlike theirs, a lens system's rays have no closed-form bound: distortion,
// aberrations and vignetting move them. So the bound is measured and then
// checked. At set-up, rays from a grid of film points over each exit-pupil
// polygon give, per grid cell, the range of each ray's screen point s in
//     p(z) = l (1 - k z) + s z
// (camera axes, z from a plane behind every ray origin; l the ray's lateral
// point on that plane, |l| <= R per axis; k chosen so that the rays of the
// film centre cross near one depth), widened by a margin. In the render, every
// traced batch is checked against its tile's bound (lens_rays_within) before
// its rays reach the scene; a ray outside it makes the tile test every
// primitive from then on. So the cull only skips what no ray of the tile
// can meet, and the image is the same bit for bit with or without it
// (tests/test_lens_pencil.py).
#pragma once

#include <memory>
#include <vector>

#include "cameras/camera_pencil.h"
#include "lens/lens_ray_table.h"
#include "lens/lens_trace.h"
#include "vec.h"

namespace lc {

struct LensSystemCamera;

// One tile's bound in the lens frame (mm, +z toward the film), as the check
// reads it: a ray passes when its origin is not behind the pencil plane
// (lens-frame z pencil_z_mm; the pencil holds its line in front of that
// plane), it heads toward the scene, and its l and s lie within radius_mm and
// [screen_lo, screen_hi] per axis (k_per_mm: k per mm).
struct LensPencilCheck {
    double pencil_z_mm, radius_mm, k_per_mm;
    double screen_lo[2], screen_hi[2];
};

// Whether every lane of b that alive marks lies within check's bound. In
// double, from the traced rays before they are rounded to float: the
// rounding moves a ray by far less than may_meet_ball's margin.
bool lens_rays_within(const LensPencilCheck& check, const LensRayBatch& b, const bool* alive);
// The same for the lens-ray table's float rays, in float. Its rounding (a
// few float epsilons of the rays' lateral reach, under 1e-6 relative) is,
// like the rays' own rounding above, far below may_meet_ball's 1e-5.
bool lens_rays_within(const LensPencilCheck& check, const LensRaysF& b, const bool* alive);

// For each mirror m (bit 0: x turned over, bit 1: y) whose checks[m] is not
// null: whether every lane of b that alive[m] marks, turned over as m says,
// lies within checks[m] (the mirrored table path: one pass for the four
// images of the same rays). The checks share their pencil plane, radius and
// focus (a LensPencils' own); each answer is lens_rays_within's for the
// mirrored rays, bit for bit (reflected_check, below).
void lens_rays_within_mirrors(const LensPencilCheck* const checks[4], const LensRaysF& b, const bool* const alive[4],
                              bool within[4]);
// The same for traced rays, in double (as lens_rays_within's).
void lens_rays_within_mirrors(const LensPencilCheck* const checks[4], const LensRayBatch& b,
                              const bool* const alive[4], bool within[4]);

// The check that rays pass exactly when their mirror images (origins and
// directions turned over in the lens frame's x for mirror bit 0, in y for
// bit 1: what the reflected film and pupil points trace to) pass check: its
// screen window reflected. The test's arithmetic is odd in x and in y, and
// IEEE rounding is symmetric, so the answers are the same for every ray, not
// only nearly.
inline LensPencilCheck reflected_check(LensPencilCheck check, unsigned mirror) {
    for (int a = 0; a < 2; ++a) {
        if (!((mirror >> a) & 1u)) continue;
        const double lo = check.screen_lo[a], hi = check.screen_hi[a];
        check.screen_lo[a] = -hi, check.screen_hi[a] = -lo;
    }
    return check;
}

class LensPencils {
  public:
    // Measured from camera's own rays (its pupil, trace and film); a camera
    // whose rays turn back from the scene anywhere gets no pencils. open:
    // the rays the band rays send (lens_system_bands.cpp), traced at d with
    // the rims stopping none and kept where some band of the spectrum
    // passes, which holds those a rim stops at d but not in blue.
    static std::shared_ptr<const LensPencils> of(const LensSystemCamera& camera, bool open = false);

    // The bound of the rays through raster rectangle [x0, x1] x [y0, y1]:
    // as a pencil in world space for the cull, and as the check of the
    // traced rays. False when a cell it covers has no bound.
    bool tile(const Frame& world_from_camera, double entrance_pupil_z_mm, double x0_px, double y0_px, double x1_px,
              double y1_px, CameraPencil* pencil, LensPencilCheck* check) const;

    // A copy whose screen ranges are each shrunk to its midpoint, so that
    // almost every traced batch leaves its pencil: the tests' way to run the
    // render's fallback (test every primitive) everywhere.
    std::shared_ptr<const LensPencils> collapsed() const;

  private:
    struct Cell {
        bool bounded = false;  // rays from its corners that turn away from the scene: none
        double screen_lo[2] = {INFINITY, INFINITY}, screen_hi[2] = {-INFINITY, -INFINITY};
    };

    int columns_ = 0, rows_ = 0;              // grid cells over the film
    double cells_per_px_x_ = 0.0, cells_per_px_y_ = 0.0;
    double pencil_z_mm_ = 0.0, radius_mm_ = 0.0, k_per_mm_ = 0.0;
    std::vector<Cell> cells_;
};

}  // namespace lc
