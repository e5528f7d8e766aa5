#include "solid_faces.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <set>

#include "cpu_kernels.h"
#include "sphere_lanes.h"

namespace lc {

SolidFaces::SolidFaces(const float* corners, const int32_t* solid, int n) {
    // Solid ids as given -> indices into solids_, with each solid's corner sum.
    std::map<int32_t, int> index_of;
    std::vector<double> centroid_sum;  // 3 per solid
    std::vector<int> corner_count;
    for (int k = 0; k < n; ++k) {
        if (solid[k] < 0) continue;
        const auto [it, added] = index_of.emplace(solid[k], int(solids_.size()));
        if (added) {
            Bounds b;
            for (int a = 0; a < 3; ++a) b.lo[a] = INFINITY, b.hi[a] = -INFINITY;
            b.margin_m = 1.0;  // the scale, then the margin: below
            solids_.push_back(b);
            centroid_sum.insert(centroid_sum.end(), 3, 0.0);
            corner_count.push_back(0);
        }
        const int s = it->second;
        Bounds& b = solids_[size_t(s)];
        for (int c = 0; c < 4; ++c)
            for (int a = 0; a < 3; ++a) {
                const double x = corners[12 * k + 3 * c + a];
                b.lo[a] = std::min(b.lo[a], x), b.hi[a] = std::max(b.hi[a], x);
                b.margin_m = std::max(b.margin_m, std::fabs(x));
                centroid_sum[3 * size_t(s) + size_t(a)] += x;
            }
        corner_count[size_t(s)] += 4;
    }
    for (Bounds& b : solids_) b.margin_m *= 64.0 * 0x1p-24;
    for (int k = 0; k < n; ++k) {
        if (solid[k] < 0) continue;
        Face f;
        f.quad = k, f.solid = index_of.at(solid[k]);
        const float* c = corners + 12 * k;
        double e1[3], e2[3], from_centre[3];
        for (int a = 0; a < 3; ++a) {
            e1[a] = double(c[3 + a]) - c[a], e2[a] = double(c[9 + a]) - c[a];
            from_centre[a] = c[a] - centroid_sum[3 * size_t(f.solid) + size_t(a)] / corner_count[size_t(f.solid)];
        }
        double m[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        const double length = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
        if (!(length > 0.0) || !std::isfinite(length)) continue;  // no plane: never skipped
        // The corners' centroid is inside a convex solid: outward points away from it.
        const double side = m[0] * from_centre[0] + m[1] * from_centre[1] + m[2] * from_centre[2];
        const double sign = side < 0.0 ? -1.0 : 1.0;
        for (int a = 0; a < 3; ++a) f.outward[a] = sign * m[a] / length;
        f.offset_m = f.outward[0] * c[0] + f.outward[1] * c[1] + f.outward[2] * c[2];
        faces_.push_back(f);
    }
    face_of_quad_.assign(size_t(std::max(n, 0)), -1);
    for (size_t f = 0; f < faces_.size(); ++f) face_of_quad_[size_t(faces_[f].quad)] = int(f);
    static std::atomic<uint64_t> constructed{0};
    if (!faces_.empty()) id_ = ++constructed;
}

uint64_t SolidFaces::solid_mates(int quad) const {
    const int f = quad < int(face_of_quad_.size()) ? face_of_quad_[size_t(quad)] : -1;
    if (f < 0) return 0;
    uint64_t mates = 0;
    for (const Face& g : faces_)
        if (g.solid == faces_[size_t(f)].solid && g.quad < 64) mates |= uint64_t(1) << g.quad;
    return mates;
}

int SolidFaces::faces_met(const int32_t* solid, int n) {
    std::set<int32_t> solids;
    int lone = 0;
    for (int k = 0; k < n; ++k) {
        if (solid[k] < 0) ++lone;
        else solids.insert(solid[k]);
    }
    return lone + 3 * int(solids.size());
}

uint64_t SolidFaces::facing(const double* lo, const double* hi) const {
    uint64_t mask = kAllCandidates;
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(lo[a]) || !std::isfinite(hi[a])) return mask;  // no bounds to decide by
    int solid = -1;
    bool apart = false;
    for (const Face& f : faces_) {
        if (f.solid != solid) {  // a solid's faces come together (quads in scene order)
            solid = f.solid;
            const Bounds& s = solids_[size_t(solid)];
            apart = false;
            for (int a = 0; a < 3; ++a) apart |= (lo[a] > s.hi[a] + s.margin_m) | (hi[a] < s.lo[a] - s.margin_m);
        }
        if (!apart || f.quad >= 64) continue;
        // The box's point farthest out along the face's normal
        double reach = 0.0;
        for (int a = 0; a < 3; ++a) reach += f.outward[a] * (f.outward[a] > 0.0 ? hi[a] : lo[a]);
        if (reach < f.offset_m - solids_[size_t(solid)].margin_m) mask &= ~(uint64_t(1) << f.quad);
    }
    return mask;
}

LC_BUILT_PER_ISA uint64_t SolidFaces::first_hits_from(const float* const origin[3], const int* active,
                                                      OriginRegion* region) const {
    if (faces_.empty()) return kAllCandidates;
    constexpr int N = kSphereLanes;
    // The common case first: every active origin inside the region (a NaN is
    // not), tested lane by lane without a branch.
    if (region->solids_id == id_) {
        int outside = 0;
        for (int i = 0; i < N; ++i) {
            bool in = true;
            for (int a = 0; a < 3; ++a) in &= (origin[a][i] >= region->lo[a]) & (origin[a][i] <= region->hi[a]);
            outside |= (active[i] != 0) & !in;
        }
        if (!outside) return region->quads;
    }
    // The region grown to take the active origins in (the first packet: their box).
    const bool fresh = region->solids_id != id_;
    region->solids_id = id_;
    for (int a = 0; a < 3; ++a) {
        float low = fresh ? INFINITY : region->lo[a], high = fresh ? -INFINITY : region->hi[a];
        bool nan = false;
        for (int i = 0; i < N; ++i) {
            if (!active[i]) continue;
            const float x = origin[a][i];
            nan |= x != x;
            low = std::min(low, x), high = std::max(high, x);
        }
        // A NaN origin: the whole space, where every quad stays (facing), from now on.
        region->lo[a] = nan ? -INFINITY : low, region->hi[a] = nan ? INFINITY : high;
    }
    double box_lo[3], box_hi[3];
    for (int a = 0; a < 3; ++a) box_lo[a] = region->lo[a], box_hi[a] = region->hi[a];
    region->quads = facing(box_lo, box_hi);
    return region->quads;
}

uint64_t SolidFaces::blocking_toward(const float light_m[3]) const {
    const double p[3] = {light_m[0], light_m[1], light_m[2]};
    return facing(p, p);
}

}  // namespace lc
