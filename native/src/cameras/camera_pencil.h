// The camera rays of one tile of the film, as one bound: a per-tile cull of
// the own spheres and quads (sphere_lanes.h, quad_lanes.h) that no camera
// ray of the tile can meet, so that their per-packet culls are not run at
// all. Most primitives lie outside a 16 x 16 pixel tile's view, yet each
// camera packet ran every sphere's and quad's float cull against its 16
// rays (the camera rays' tests were a sixth of lit_showcase's render, perf);
// culled per tile, lit_showcase's thin lens fell from 47.2 to 45.0 ns per
// sample and peers_lit's from 59.8 to 53.3 (A/B, 2 threads).
//
// A thin lens's or pinhole's rays through a tile form a pencil: in the
// camera frame (x right, y up, z forward, lens at z = 0) a ray is
//     p(z) = l (1 - k z) + s z,     z >= 0,
// l a lens point (|l| <= lens_radius_m; 0 for the pinhole), s a point of the
// tile's screen rectangle (FilmToScreen, z = 1) and k = 1 / focus distance.
// At depth z, p's x lies within [s_lo z - R |1 - k z|, s_hi z + R |1 - k z|]
// (likewise y): the upper end is convex in z, the lower concave, so over a
// depth range [z0, z1] each is widest at z0 or z1. A ball whose depth range
// and lateral extent miss that box meets no ray of the pencil. The test is
// in double with a margin of 1e-5 of the distances (the rays are rounded to
// float, a relative 6e-8): it only skips what cannot be hit, so the images
// are the same bit for bit.
#pragma once

#include "vec.h"

namespace lc {

struct CameraPencil {
    Frame world_from_camera;     // the lens centre and the camera's axes
    double lens_radius_m = 0.0;  // the farthest lens point from the centre (0: a pinhole)
    double inverse_focus_per_m = 0.0;
    double screen_lo[2] = {}, screen_hi[2] = {};  // the tile's screen rectangle, x and y at z = 1
    // Whether the rays start on the lens disk (the thin lens, the pinhole):
    // then the boxes' faces behind the whole disk are culled per tile. A lens
    // system's rays leave from its front surface (lens_pencil.h): see
    // origins_in_box. (Commit 9428382 measured such a box 3 ns a sample
    // slower than each packet's own origins on lit_showcase; in session 54
    // the per-packet test was 4 % of a mirrored table render's perf samples
    // on showcase, a third of that with the box, the end-to-end change
    // within the host's spread.)
    bool origins_on_lens_disk = true;
    // Else, whether they start within a box (world space, m; widened past
    // their rounding): a lens system's round its first surface
    // (LensSystemCamera::bound_origins), its faces culled likewise.
    bool origins_in_box = false;
    double origins_lo_m[3] = {}, origins_hi_m[3] = {};
    // A moving camera's rays over the shutter: the pencil's translated by an
    // offset within sweep_half_m of sweep_mid_m (world space, m; zero for a
    // still camera). A ball meets such a ray only if the ball moved back by
    // the offset meets the pencil, so the test takes the ball at
    // centre - sweep_mid_m with sweep_half_m more radius (render_tile.h, cull_tile).
    Vec3d sweep_mid_m{0.0, 0.0, 0.0};
    double sweep_half_m = 0.0;

    // Whether some ray of the pencil may come within radius_m of centre_m
    // (world space). A value not finite keeps the ball.
    bool may_meet_ball(const float centre_m[3], float radius_m) const;
};

// The pencil through raster rectangle [x0, x1] x [y0, y1] (pixels; the
// film's FilmToScreen) of a lens whose farthest aperture point is
// lens_radius_m from its centre, focused at 1 / inverse_focus_per_m.
template <class Film>
CameraPencil pencil_of(const Frame& world_from_camera, const Film& film, double lens_radius_m,
                       double inverse_focus_per_m, double x0_px, double y0_px, double x1_px, double y1_px) {
    CameraPencil p;
    p.world_from_camera = world_from_camera;
    p.lens_radius_m = lens_radius_m;
    p.inverse_focus_per_m = inverse_focus_per_m;
    // Screen x grows with raster x, screen y against raster y (FilmToScreen).
    p.screen_lo[0] = (2.0 * x0_px / film.width_px - 1.0) * film.screen_half_width;
    p.screen_hi[0] = (2.0 * x1_px / film.width_px - 1.0) * film.screen_half_width;
    p.screen_lo[1] = (1.0 - 2.0 * y1_px / film.height_px) * film.screen_half_height;
    p.screen_hi[1] = (1.0 - 2.0 * y0_px / film.height_px) * film.screen_half_height;
    return p;
}

}  // namespace lc
