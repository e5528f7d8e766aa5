// The lens system's rays by table look-up instead of a trace per sample.
//
// Within one exit-pupil ring (exit_pupil.h) the ray a sample makes is a
// smooth function of three numbers: the film radius r, and the pupil sample
// (sqrt(u.x), u.y) that the pick maps to a point of the ring's polygon (the
// lens being round, the film point's azimuth only rotates the result). The
// table holds that function, traced once in double at the nodes of a grid
// (both ends of each ring x radial x around), and a sample interpolates it
// trilinearly: where the ray leaves the first surface, its direction, its
// weight (cos^4 theta times the polygon's area), and a margin, the least of
// (rim - height) / rim over the surfaces (and the blades' edges), traced
// without the rims, whose sign says whether the ray gets through. Where a
// node's ray misses a surface or is totally reflected the margin means
// nothing: samples in cells touching such a node go to the exact trace.
//
// The table holds half of each ring's pupil: the pick is symmetric about the
// meridional plane (u.y and 1 - u.y give points mirrored in y, to 1e-9 of
// their traced rays on the lenses of tests/test_lens_ray_table.py), so a
// sample with u.y > 1/2 reads 1 - u.y's values and turns its y components
// over. Half the nodes to trace and half the cache lines a ring's samples
// share.
//
// Interpolating rays is exact wherever the ray is linear in the sample; for
// an aberration-free lens the rays of one film point all pass through its
// image, and so do their interpolations, so images in focus keep their
// sharpness. What is left (aberrations' curvature, where the binding rim
// changes) is measured against the exact trace (tests/test_lens_ray_table.py).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "lens/exit_pupil.h"
#include "lens/lens_trace.h"
#include "vec.h"

namespace lc {

// What a node holds for each end of its ring (the ray of a film point on +x).
// A node whose unclipped trace failed holds NaN throughout: a sample in a
// cell touching it is traced (a cell's corners are read even at weight 0).
// The nodes of a ring outside the image circle hold margin -1: dead.
enum LensTableValue : int {
    kTableOriginX,     // where the ray leaves the first surface, mm
    kTableOriginY,
    kTableOriginZ,
    kTableDirectionX,  // unit direction toward the scene (interpolated, then normalised)
    kTableDirectionY,
    kTableDirectionZ,
    kTableWeight,      // cos^4 theta at the film times the polygon's area, mm^2
    kTableMargin,      // > 0: the ray passes every rim
    kTableValues
};

// One (radial, around) node of a ring: its values at the ring's inner and
// outer film radius, one cache line.
struct alignas(64) LensTableNode {
    float end[2][kTableValues];
};

struct LensRayTable {
    int rings = 0;                 // the exit pupil's
    int radial_cells = 0, around_cells = 0;  // around_cells over the whole of u.y (even)
    double rings_per_mm = 0.0;
    std::vector<LensTableNode> nodes;  // [ring][radial][around, u.y from 0 to 1/2]

    // Nodes around a ring's half pupil: u.y = j / around_cells for j up to half.
    int around_nodes() const { return around_cells / 2 + 1; }
    size_t node_index(int ring, int radial, int around) const {
        return (size_t(ring) * size_t(radial_cells + 1) + size_t(radial)) * size_t(around_nodes()) + size_t(around);
    }
    const LensTableNode* node(int ring, int radial, int around) const { return &nodes[node_index(ring, radial, around)]; }
    LensTableNode* node(int ring, int radial, int around) { return &nodes[node_index(ring, radial, around)]; }
};

// Traced through elements (the camera's, blades included) at the nodes of
// the pupil's rings, radial_cells x around_cells cells each (around_cells
// even; half of them traced); film at film_z_mm.
std::shared_ptr<const LensRayTable> build_lens_ray_table(const std::vector<LensElement>& elements,
                                                         const ExitPupil& pupil, double film_z_mm,
                                                         int radial_cells, int around_cells);

// The rays of lanes [0, n): raster positions and lens samples in,
// origins (on the first surface, to interpolation), unit directions, alive
// and weight_mm2 (each lane's cos^4 theta times pupil area) out. Lanes
// whose cell touches a failed node come back not alive with exact[i] set:
// the caller traces them. (Built per instruction set; every build gives the
// same bits.)
// Where a raster position lies on the film (lens frame, mm; the image is
// inverted): x = (centre_x_px - raster x) * mm_per_px_x, y = (raster y -
// centre_y_px) * mm_per_px_y.
struct FilmPlacement {
    float centre_x_px, centre_y_px, mm_per_px_x, mm_per_px_y;
};

// The table's rays in single precision, as they are interpolated: the
// render's path goes on in float to the world (lens_to_world.h) without a
// double column between.
struct LensRaysF {
    float ox[kLensBatch], oy[kLensBatch], oz[kLensBatch];
    float dx[kLensBatch], dy[kLensBatch], dz[kLensBatch];
    float weight_mm2[kLensBatch];  // cos^4 theta times pupil area
    bool alive[kLensBatch];
};

void look_up_lens_rays(const LensRayTable& table, FilmPlacement film, const Point2f* raster_px,
                       const Point2f* lens_sample, int n, LensRaysF* out, bool* exact);

// The unclipped trace's margin (see above): false when the ray misses a
// surface, is totally reflected or turns back; otherwise the ray left the
// first surface and margin holds the least relative clearance of any rim.
bool trace_with_margin(const std::vector<LensElement>& elements, LensRay* ray, double* margin);

}  // namespace lc
