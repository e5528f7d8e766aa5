// The lens seen from the scene: every surface mirrored in z (z -> -z), so
// that the film-to-scene trace through the mirrored lens follows a ray from
// the scene toward the film. It serves back-tracing: where on the film a ray
// leaving the lens came from at another wavelength (the chromatic shift of a
// fixed scene ray, lens_system.h's film_points_from).
//
// Mirroring keeps every test of the trace: a sphere's cap condition c (z - v)
// < 1 holds for the mirrored c and v alike; the normal (0, 0, 1) - c (p - v)
// is the mirrored surface's; refraction goes from the side the ray comes
// from to the other, so the two indices swap; x and y, and with them the
// apertures and a bladed stop's edges, are unchanged.
#pragma once

#include <utility>
#include <vector>

#include "lens/lens_trace.h"

namespace lc {

// elements (scene side first) mirrored in z, the former film side first.
inline std::vector<LensElement> reversed_lens(const std::vector<LensElement>& elements) {
    std::vector<LensElement> out(elements.rbegin(), elements.rend());
    for (LensElement& e : out) {
        e.curvature_per_mm = -e.curvature_per_mm;
        e.vertex_z_mm = -e.vertex_z_mm;
        std::swap(e.n_scene_side, e.n_film_side);
    }
    return out;
}

// Rays that left the lens, in the mirrored frame and followed back toward
// the film: the origin (x, y, z) -> (x, y, -z), the direction mirrored and
// reversed, (dx, dy, dz) -> (-dx, -dy, dz).
inline void mirror_for_back_trace(const LensRayBatch& leaving, LensRayBatch* back) {
    for (int i = 0; i < kLensBatch; ++i) {
        back->ox[i] = leaving.ox[i], back->oy[i] = leaving.oy[i], back->oz[i] = -leaving.oz[i];
        back->dx[i] = -leaving.dx[i], back->dy[i] = -leaving.dy[i], back->dz[i] = leaving.dz[i];
        back->alive[i] = leaving.alive[i];
    }
}

// Where lane i of a back-trace's result (the mirrored frame) meets the film
// plane, the film at film_z_mm in the lens frame: x and y, lens frame.
inline void back_traced_film_point(const LensRayBatch& back, int i, double film_z_mm, double* x_mm, double* y_mm) {
    const double t = (-film_z_mm - back.oz[i]) / back.dz[i];
    *x_mm = back.ox[i] + back.dx[i] * t, *y_mm = back.oy[i] + back.dy[i] * t;
}

}  // namespace lc
