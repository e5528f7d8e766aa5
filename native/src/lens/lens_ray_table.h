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

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
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

// The grid a table's nodes sit on (this table's, and lens_band_table.h's):
// per exit-pupil ring, both of its ends x radial x around, half the pupil.
struct LensTableGrid {
    int rings = 0;                 // the exit pupil's
    int radial_cells = 0, around_cells = 0;  // around_cells over the whole of u.y (even)
    double rings_per_mm = 0.0;

    LensTableGrid() = default;
    LensTableGrid(const ExitPupil& pupil, int radial, int around)
        : rings(kPupilSegments), radial_cells(radial), around_cells(around), rings_per_mm(pupil.segments_per_mm()) {}

    // Nodes around a ring's half pupil: u.y = j / around_cells for j up to half.
    int around_nodes() const { return around_cells / 2 + 1; }
    size_t node_count() const { return size_t(rings) * size_t(radial_cells + 1) * size_t(around_nodes()); }
    size_t node_index(int ring, int radial, int around) const {
        return (size_t(ring) * size_t(radial_cells + 1) + size_t(radial)) * size_t(around_nodes()) + size_t(around);
    }

    // Calls node(ring, end, film radius mm, sqrt(u.x), u.y, node index) for
    // every node of the rings the pupil covers, rings in parallel: each node
    // on its own, so the same table whatever the threads.
    template <class Node>
    void for_each_node(const ExitPupil& pupil, Node node) const;
};

struct LensRayTable : LensTableGrid {
    std::vector<LensTableNode> nodes;  // [ring][radial][around, u.y from 0 to 1/2]
    // Round the axis, the farthest and the z range of the nodes' finite
    // origins (lens frame, mm): an interpolated origin, a weighted mean of
    // its cell's corners turned about the axis, lies within them (to the
    // float rounding of the interpolation).
    double origin_radius_mm = 0.0, origin_z_lo_mm = 0.0, origin_z_hi_mm = 0.0;

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

// Where each lane of a batch reads a table's grid: its film point (lens
// frame, mm) and radius, the first of its cell's corners, and how far into
// the cell (ring, radial, around) it lies; y_sign -1 where u.y is past 1/2 (read at
// 1 - u.y, the y values turned over). Samples [0, n), the rest as sample 0.
struct alignas(64) TableCellLanes {
    alignas(64) float x[kLensBatch];
    alignas(64) float y[kLensBatch];
    alignas(64) float r[kLensBatch];
    alignas(64) float fr[kLensBatch];
    alignas(64) float fs[kLensBatch];
    alignas(64) float fu[kLensBatch];
    alignas(64) float y_sign[kLensBatch];
    alignas(64) int first_node[kLensBatch];
};
// (Inline in each look-up, so that it is built for the look-up's instruction set.)
__attribute__((always_inline)) inline void find_table_cells(const LensTableGrid& grid, FilmPlacement film,
                                                            const Point2f* raster_px, const Point2f* lens_sample,
                                                            int n, TableCellLanes* out) {
    const int last_ring = grid.rings - 1;
    const int around_nodes = grid.around_nodes();
    const int ring_nodes = (grid.radial_cells + 1) * around_nodes;
    const int last_radial = grid.radial_cells - 1, last_around = around_nodes - 2;
    const float rings_per_mm = float(grid.rings_per_mm);
    const float radial_cells = float(grid.radial_cells), around_cells = float(grid.around_cells);
    // Plain lane loops, which GCC vectorises (float lanes).
    float px[kLensBatch], py[kLensBatch], ux[kLensBatch], uy[kLensBatch];
    if (n == kLensBatch) {  // the common whole batch: a straight copy, which vectorises
        for (int i = 0; i < kLensBatch; ++i)
            px[i] = raster_px[i].x, py[i] = raster_px[i].y, ux[i] = lens_sample[i].x, uy[i] = lens_sample[i].y;
    } else {
        for (int i = 0; i < kLensBatch; ++i) {
            const int k = i < n ? i : 0;
            px[i] = raster_px[k].x, py[i] = raster_px[k].y, ux[i] = lens_sample[k].x, uy[i] = lens_sample[k].y;
        }
    }
    for (int i = 0; i < kLensBatch; ++i) {
        const float x = (film.centre_x_px - px[i]) * film.mm_per_px_x, y = (py[i] - film.centre_y_px) * film.mm_per_px_y;
        out->x[i] = x, out->y[i] = y;
        out->r[i] = std::sqrt(x * x + y * y);
        const float ring_at = out->r[i] * rings_per_mm;
        const int ring = std::min(int(ring_at), last_ring);
        const float ring_fraction = ring_at - float(ring);
        out->fr[i] = ring_fraction < 1.0f ? ring_fraction : 1.0f;
        const float radial_at = std::sqrt(ux[i]) * radial_cells;
        const int radial = std::min(int(radial_at), last_radial);
        out->fs[i] = radial_at - float(radial);
        // u.y itself up to 1/2, else 1 - u.y (exact past 1/2); min and a
        // product rather than a condition, so that GCC vectorises the loop.
        out->y_sign[i] = 1.0f - 2.0f * float(uy[i] > 0.5f);
        const float around_at = std::min(uy[i], 1.0f - uy[i]) * around_cells;
        const int around = std::min(int(around_at), last_around);
        out->fu[i] = around_at - float(around);
        out->first_node[i] = ring * ring_nodes + radial * around_nodes + around;
    }
}

// Asks for the cache lines of lanes [0, n)'s four cell corners (nodes, a
// table's on the grid of find_table_cells), all of them before any is read,
// so that their misses overlap (this table and the band table are more than
// this CPU's L2).
template <class Node>
__attribute__((always_inline)) inline void prefetch_table_cells(const Node* nodes, const TableCellLanes& cells, int n,
                                                                int around_nodes) {
    for (int i = 0; i < n; ++i) {
        const Node* n00 = nodes + cells.first_node[i];
        __builtin_prefetch(n00), __builtin_prefetch(n00 + 1);
        __builtin_prefetch(n00 + around_nodes), __builtin_prefetch(n00 + around_nodes + 1);
    }
}

void look_up_lens_rays(const LensRayTable& table, FilmPlacement film, const Point2f* raster_px,
                       const Point2f* lens_sample, int n, LensRaysF* out, bool* exact);

template <class Node>
void LensTableGrid::for_each_node(const ExitPupil& pupil, Node node) const {
    tbb::parallel_for(0, rings, [&](int ring) {
        if (pupil.segment(ring).empty) return;
        for (int end = 0; end < 2; ++end) {
            const double film_r_mm = double(ring + end) / rings_per_mm;
            for (int i = 0; i <= radial_cells; ++i)
                for (int j = 0; j < around_nodes(); ++j)
                    node(ring, end, film_r_mm, double(i) / radial_cells, float(j) / float(around_cells),
                         node_index(ring, i, j));
        }
    });
}

// The unclipped trace's margin (see above): false when the ray misses a
// surface, is totally reflected or turns back; otherwise the ray left the
// first surface and margin holds the least relative clearance of any rim.
bool trace_with_margin(const std::vector<LensElement>& elements, LensRay* ray, double* margin);

}  // namespace lc
