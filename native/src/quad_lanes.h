// A few still quads (boxes' faces, rectangles: parallelograms) the render
// intersects itself, a packet of rays at a time, as it does a few spheres
// (sphere_lanes.h), instead of handing them to Embree. On showcase and
// lit_showcase (one box and one rectangle: 7 quads) Embree then traces no
// camera or shadow ray at all, and its robust traversal, which keeps rays from
// slipping between quads that share an edge, had cost a fifth of its time
// there (bench/bench_peers.py, native_thin_not_robust).
//
// The test runs in double: the plane's distance t = (v0 - o) . n / (d . n),
// then the hit's coordinates (u, v) along the two edges from dual vectors,
// accepted on [-margin, 1 + margin]. The margin is a few float steps of the
// quad's largest coordinate (in edge lengths), and past a side two quads
// share it widens as 1 / sin of a grazing ray's angle to the plane (down to
// 1/256), so that where their float corners round them apart (or out of one
// plane) their tests overlap by a hair instead of leaving a gap: watertight
// by construction down to that angle.
// A ray in the quad's plane (d . n = 0) misses it (t is infinite or NaN).
#pragma once

#include <vector>

#include "sphere_lanes.h"

namespace lc {

// One quad, set up once (make_own_quad): corner v0, normal n = e1 x e2, the
// dual vectors a1, a2 (p - v0 = u e1 + v e2 gives u = (p - v0) . a1, v = ...
// . a2), the margins in u and v, and for the cull a bounding sphere (centre
// xyz, radius, float) and the unit normal (float) the hit reports.
struct OwnQuad {
    double v0[3], n[3], a1[3], a2[3], margin_u, margin_v;
    // The margins' widening for grazing rays past a side shared with another
    // quad (on_edge_span, quad_lanes.cpp): cap_u[0] past u = 0, cap_u[1] past u = 1.
    double graze2_u, graze2_v, cap_u[2], cap_v[2], slack_m;
    float bound[4], unit_normal[3];
};

// The quad with corners v0, v1, v2, v3 (in order round it, float xyz each),
// or false when it is not a parallelogram (v2 != v1 + v3 - v0 beyond float
// rounding) or is degenerate: Embree takes such quads.
bool make_own_quad(const float* corners, OwnQuad* out);

// Lets grazing rays be taken a little past each side of quads[k] that
// another of the n quads shares (the same two corners, to the quads' float
// rounding) at a fold under 30 degrees, so that they cannot slip between the
// two (quad_lanes.cpp, on_edge_span). corners holds the quads' 4 x 3 floats
// each, as made.
void widen_shared_sides(const float* corners, int n, OwnQuad* quads);

// The most faces a ray may have to test (SolidFaces::faces_met: each lone
// quad, three of each box's six) for the render to intersect the still quads
// itself (16): one test per quad per ray grows with their count, and Embree's
// BVH does not. Once rays skipped the boxes' hidden faces (solid_faces.h) the
// own test was ahead to peers_lit's 4 boxes and wall (25 quads, 13 met:
// bench/bench_quads.py, Embree / own 1.16) and level at 19 to 31 met; before,
// with every face tested, Embree led from 13 quads. Past the limit Embree
// takes all of them. LENSCOMPARE_MAX_OWN_QUADS overrides it (0: Embree takes
// all), for tests and benchmarks that compare the two.
int max_own_quads();

// Closest hits, as spheres_closest (sphere_lanes.h): where lane i (active[i]
// set) meets a quad at t in [0, t_far[i]), t_far[i] becomes the hit distance,
// index[i] the quad and normal[.][i] its unit normal (either side); other lanes
// keep t_far and get index -1. The same kernels as the spheres'. Of quads
// met at one distance the lowest index wins, whatever the order they are
// tested in: first_quad (when given) names the quad tested first, and is set
// to the quad a lane of this packet met, the likeliest first hit of the next
// packet of neighbouring rays (the floor of a room): it shortens the rays
// before the other quads' plane culls, the same hits in fewer tests. Only
// the quads candidates names are tested (is_candidate, sphere_lanes.h).
void quads_closest(SphereKernel kernel, const OwnQuad* quads, int n, const float* const origin[3],
                   const float* const direction[3], const int* active, float* t_far, int* index,
                   float* const normal[3], int* first_quad = nullptr, uint64_t candidates = kAllCandidates);

// Whether the segments t in [0, t_far[i]] cross some quad: blocked[i] = -1
// where so (active lanes), else 0. Returns whether any lane is blocked. Shadow
// rays start lifted off their surface (shading_lanes.h), so a quad does not
// block the rays that leave it. Only the quads candidates names are tested
// (is_candidate, sphere_lanes.h).
bool quads_occluded(SphereKernel kernel, const OwnQuad* quads, int n, const float* const origin[3],
                    const float* const direction[3], const float* t_far, const int* active, int* blocked,
                    uint64_t candidates = kAllCandidates);

}  // namespace lc
