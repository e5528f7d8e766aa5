#include "quad_lanes.h"

#include <cmath>
#include <cstdlib>

#include "near_line_lanes.h"

namespace lc {
namespace {

constexpr int N = kSphereLanes;
using lanes::DoubleLanes;

// Whether a hit's coordinate w along one edge lies on the quad: within the
// margin m of [0, 1], or, past a side the quad shares with another quad and
// for a ray at a grazing slope, within m (1 + k / sin), where sin = |d . n| /
// (|n| |d|) is the sine of the ray's angle to the plane. Two quads sharing an
// edge are not in one plane once their corners round to float: a ray crossing
// the edge meets their planes up to k slack / sin apart along them, and a
// fixed margin let 1 to 3 % of rays within 1 degree of a split rectangle's
// plane through (tests/test_own_quads.py). The widened hit lies over the
// neighbour, where the ray meets it anyway; a side of its own (a lone quad's
// rim) keeps the fixed margin. cap_lo and cap_hi (past w = 0 and w = 1) stop
// the widening at sin 1/256, so that a ray almost in the plane does not report
// a hit far out along it. Both sides of the comparison squared: no root here.
[[gnu::always_inline]] inline int on_edge_span(double w, double m, double cap_lo, double cap_hi, double graze2,
                                              double dn2, double dd) {
    // Past the nearer end, in edge lengths; NaN stays NaN (a select, not fmax: GCC vectorises it)
    const double excess = -w > w - 1.0 ? -w : w - 1.0;
    const double over = excess - m;
    const double cap = w < 0.5 ? cap_lo : cap_hi;
    return (over <= 0.0) | ((excess <= cap) & (over * over * dn2 <= graze2 * dd));
}

// Lane i's distance to quad q's plane and whether the hit lies on the quad
// (within its margins), in double; t is NaN or infinite for a ray in the plane.
[[gnu::always_inline]] inline void plane_hits(const OwnQuad& q, const DoubleLanes<N>& ray, double* t_out,
                                              int* inside) {
    for (int i = 0; i < N; ++i) {
        const double dx = ray.d[0][i], dy = ray.d[1][i], dz = ray.d[2][i];
        const double fx = q.v0[0] - ray.o[0][i], fy = q.v0[1] - ray.o[1][i], fz = q.v0[2] - ray.o[2][i];
        const double dn = dx * q.n[0] + dy * q.n[1] + dz * q.n[2];
        const double t = (fx * q.n[0] + fy * q.n[1] + fz * q.n[2]) / dn;
        // The hit relative to v0: o + t d - v0
        const double rx = t * dx - fx, ry = t * dy - fy, rz = t * dz - fz;
        const double u = rx * q.a1[0] + ry * q.a1[1] + rz * q.a1[2];
        const double v = rx * q.a2[0] + ry * q.a2[1] + rz * q.a2[2];
        const double dn2 = dn * dn, dd = dx * dx + dy * dy + dz * dz;
        // NaN fails every comparison, so a ray in the plane is outside.
        inside[i] = on_edge_span(u, q.margin_u, q.cap_u[0], q.cap_u[1], q.graze2_u, dn2, dd) &
                    on_edge_span(v, q.margin_v, q.cap_v[0], q.cap_v[1], q.graze2_v, dn2, dd) & (t >= 0.0);
        t_out[i] = t;
    }
}

// Whether some active lane's segment t in [0, t_far * stretch] may cross q's
// plane: its ends are not both strictly on one side. Shadow rays mostly start
// and end on one side of a quad's plane (a floor's faces, a wall behind the
// lights): then the quad is skipped before plane_hits' division.
template <class Set>
[[gnu::always_inline]] inline bool may_cross_plane(Set set, const OwnQuad& q, const DoubleLanes<N>& ray,
                                                   const float* t_far, const int* active, double stretch) {
    alignas(64) int crosses[N];
    for (int i = 0; i < N; ++i) {
        const double fx = ray.o[0][i] - q.v0[0], fy = ray.o[1][i] - q.v0[1], fz = ray.o[2][i] - q.v0[2];
        const double start = fx * q.n[0] + fy * q.n[1] + fz * q.n[2];
        const double along = ray.d[0][i] * q.n[0] + ray.d[1][i] * q.n[1] + ray.d[2][i] * q.n[2];
        const double end = start + double(t_far[i]) * stretch * along;
        crosses[i] = -int((active[i] != 0) & !(start * end > 0.0));
    }
    return lanes::any_set<N>(set, crosses);
}

// The two culls, the plane's sides first (it skips most shadow rays), then
// the bounding sphere; stretch widens the plane cull's segment (kTieStretch).
template <class Set>
[[gnu::always_inline]] inline bool may_meet(Set set, const OwnQuad& q, const DoubleLanes<N>& ray,
                                            const float* const origin[3], const float* const direction[3],
                                            const float* t_far, const float* inv_dd, const float* origin_size,
                                            const int* active, double stretch = 1.0) {
    return may_cross_plane(set, q, ray, t_far, active, stretch) &&
           lanes::near_line<N>(set, q.bound, origin, direction, inv_dd, origin_size, active);
}

// The plane cull's stretch of t_far in the closest test: a quad whose hit
// rounds (to float) to the current t_far is still tested, so that a tie goes
// to the lower index whichever quad came first (plane_hits' t and the cull's
// ends differ by a few double roundings, far below 2^-20).
constexpr double kTieStretch = 1.0 + 0x1p-20;

template <class Set>
[[gnu::always_inline]] inline void closest_body(Set set, const OwnQuad* quads, int n, const float* const origin[3],
                                                const float* const direction[3], const int* active, float* t_far,
                                                int* index, float* const normal[3], int* first_quad,
                                                uint64_t candidates) {
    float inv_dd[N], origin_size[N];
    lanes::lane_scales<N>(origin, direction, inv_dd, origin_size);
    DoubleLanes<N> ray;
    ray.load_once(origin, direction);  // the plane culls take the lanes in double
    for (int i = 0; i < N; ++i) index[i] = -1;
    const int first = first_quad && *first_quad >= 0 && *first_quad < n ? *first_quad : 0;
    auto test = [&](int k) __attribute__((always_inline)) {
        const OwnQuad& q = quads[k];
        if (!may_meet(set, q, ray, origin, direction, t_far, inv_dd, origin_size, active, kTieStretch)) return;
        double t[N];
        int inside[N];
        plane_hits(q, ray, t, inside);
        for (int i = 0; i < N; ++i) {
            const float hit_f = float(t[i]);
            // Nearer, or as near and of a lower index (a shared edge): the
            // lowest index at the least distance, in any order.
            const bool nearer = (hit_f < t_far[i]) | ((hit_f == t_far[i]) & (index[i] > k));
            const bool take = (active[i] != 0) & (inside[i] != 0) & nearer;
            t_far[i] = take ? hit_f : t_far[i];
            index[i] = take ? k : index[i];
        }
    };
    if (n == 0) return;  // no quad to test or take a normal from
    // first, then the other candidates in order: a packet has about three
    // of a scene's quads as candidates, so the walk takes the set bits only.
    if (is_candidate(candidates, first)) test(first);
    for_each_candidate(candidates, n, first, test);
    const int index0 = index[0];
    int differ = 0;  // an OR of ints (GCC vectorises it; a chain of bools it did not)
    for (int i = 1; i < N; ++i) differ |= index[i] ^ index0;
    if (differ == 0) {  // the usual packet: one quad or none for every lane
        const OwnQuad& q = quads[index0 < 0 ? 0 : index0];
        for (int a = 0; a < 3; ++a) {
            const float value = q.unit_normal[a];  // once: the rows could alias it
            float* const row = normal[a];
            for (int i = 0; i < N; ++i) row[i] = value;
        }
        if (first_quad && index0 >= 0) *first_quad = index0;
        return;
    }
    int winner = -1;
    for (int i = 0; i < N; ++i) {
        const OwnQuad& q = quads[index[i] < 0 ? 0 : index[i]];
        for (int a = 0; a < 3; ++a) normal[a][i] = q.unit_normal[a];
        winner = winner < 0 ? index[i] : winner;
    }
    if (first_quad && winner >= 0) *first_quad = winner;
}

template <class Set>
[[gnu::always_inline]] inline bool occluded_body(Set set, const OwnQuad* quads, int n, const float* const origin[3],
                                                 const float* const direction[3], const float* t_far,
                                                 const int* active, int* blocked, uint64_t candidates) {
    float inv_dd[N], origin_size[N];
    lanes::lane_scales<N>(origin, direction, inv_dd, origin_size);
    DoubleLanes<N> ray;
    ray.load_once(origin, direction);  // the plane culls take the lanes in double
    int met[N] = {};
    for_each_candidate(candidates, n, -1, [&](int k) __attribute__((always_inline)) {
        const OwnQuad& q = quads[k];
        if (!may_meet(set, q, ray, origin, direction, t_far, inv_dd, origin_size, active)) return;
        double t[N];
        int inside[N];
        plane_hits(q, ray, t, inside);
        for (int i = 0; i < N; ++i) met[i] |= (inside[i] != 0) & (t[i] <= double(t_far[i]));
    });
    for (int i = 0; i < N; ++i) blocked[i] = (active[i] != 0) & (met[i] != 0) ? -1 : 0;
    return lanes::any_set<N>(set, blocked);
}

void closest_default(const OwnQuad* q, int n, const float* const o[3], const float* const d[3], const int* active,
                     float* t_far, int* index, float* const normal[3], int* first, uint64_t candidates) {
    closest_body(lanes::PortableSet{}, q, n, o, d, active, t_far, index, normal, first, candidates);
}
[[gnu::target("avx2")]] void closest_avx2(const OwnQuad* q, int n, const float* const o[3], const float* const d[3],
                                          const int* active, float* t_far, int* index, float* const normal[3],
                                          int* first, uint64_t candidates) {
    closest_body(lanes::Avx2Set{}, q, n, o, d, active, t_far, index, normal, first, candidates);
}
[[gnu::target("avx512f")]] void closest_avx512(const OwnQuad* q, int n, const float* const o[3],
                                               const float* const d[3], const int* active, float* t_far, int* index,
                                               float* const normal[3], int* first, uint64_t candidates) {
    closest_body(lanes::Avx512Set{}, q, n, o, d, active, t_far, index, normal, first, candidates);
}

bool occluded_default(const OwnQuad* q, int n, const float* const o[3], const float* const d[3], const float* t_far,
                      const int* active, int* blocked, uint64_t candidates) {
    return occluded_body(lanes::PortableSet{}, q, n, o, d, t_far, active, blocked, candidates);
}
[[gnu::target("avx2")]] bool occluded_avx2(const OwnQuad* q, int n, const float* const o[3], const float* const d[3],
                                           const float* t_far, const int* active, int* blocked,
                                           uint64_t candidates) {
    return occluded_body(lanes::Avx2Set{}, q, n, o, d, t_far, active, blocked, candidates);
}
[[gnu::target("avx512f")]] bool occluded_avx512(const OwnQuad* q, int n, const float* const o[3],
                                                const float* const d[3], const float* t_far, const int* active,
                                                int* blocked, uint64_t candidates) {
    return occluded_body(lanes::Avx512Set{}, q, n, o, d, t_far, active, blocked, candidates);
}

void cross(const double* a, const double* b, double* out) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}
double dot(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

}  // namespace

// How many slacks two quads sharing an edge may stand apart across it: each
// one's corners may have rounded by a slack (make_own_quad).
constexpr double kGrazeSlack = 2.0;
// The shallowest slope (sine) down to which a shared side's margin widens.
constexpr double kShallowestGraze = 1.0 / 256.0;

bool make_own_quad(const float* corners, OwnQuad* out) {
    const float* c0 = corners;
    const float* c1 = corners + 3;
    const float* c2 = corners + 6;
    const float* c3 = corners + 9;
    double e1[3], e2[3], size = 1.0;
    for (int a = 0; a < 12; ++a) size = std::fmax(size, std::fabs(double(corners[a])));
    for (int a = 0; a < 3; ++a) e1[a] = double(c1[a]) - c0[a], e2[a] = double(c3[a]) - c0[a];
    // A few float steps at the quad's largest coordinate: how far its corners
    // may have rounded from where the scene put them.
    const double slack_m = 8.0 * 0x1p-24 * size;
    for (int a = 0; a < 3; ++a)
        if (std::fabs(double(c2[a]) - (double(c1[a]) + e2[a])) > slack_m) return false;  // not a parallelogram
    double n[3];
    cross(e1, e2, n);
    const double nn = dot(n, n), e1_length = std::sqrt(dot(e1, e1)), e2_length = std::sqrt(dot(e2, e2));
    if (!(nn > 0.0) || !std::isfinite(nn)) return false;  // degenerate: no area
    cross(e2, n, out->a1);
    cross(n, e1, out->a2);
    for (int a = 0; a < 3; ++a) {
        out->v0[a] = c0[a], out->n[a] = n[a];
        out->a1[a] /= nn, out->a2[a] /= nn;
        out->unit_normal[a] = float(n[a] / std::sqrt(nn));
    }
    out->margin_u = slack_m / e1_length, out->margin_v = slack_m / e2_length;
    // The grazing widening (on_edge_span): m k / sin with k = kGrazeSlack, as
    // (m k)^2 |n|^2 against (excess - m)^2 (d . n)^2 / |d|^2; none until
    // widen_shared_sides finds a neighbour.
    out->graze2_u = out->margin_u * out->margin_u * kGrazeSlack * kGrazeSlack * nn;
    out->graze2_v = out->margin_v * out->margin_v * kGrazeSlack * kGrazeSlack * nn;
    out->cap_u[0] = out->cap_u[1] = out->margin_u;
    out->cap_v[0] = out->cap_v[1] = out->margin_v;
    out->slack_m = slack_m;
    // Bounding sphere: the centre, and half the longer diagonal
    double diagonal_sum = 0.0, diagonal_difference = 0.0;
    for (int a = 0; a < 3; ++a) {
        out->bound[a] = float(c0[a] + 0.5 * (e1[a] + e2[a]));
        diagonal_sum += (e1[a] + e2[a]) * (e1[a] + e2[a]);
        diagonal_difference += (e1[a] - e2[a]) * (e1[a] - e2[a]);
    }
    // A ray taken in a grazing margin passes within (1 + kGrazeSlack) slack of a side
    out->bound[3] = float(0.5 * std::sqrt(std::fmax(diagonal_sum, diagonal_difference)) +
                          (2.0 + kGrazeSlack) * slack_m);
    return true;
}

// Whether two quads' planes are within 30 degrees of each other (either
// facing). Across a sharper fold (a box's edge) a ray grazing one quad meets
// the other steeply, within its fixed margin: the widening is not needed
// there, and would let a face the ray passes outside of report a hit.
static bool nearly_one_plane(const OwnQuad& a, const OwnQuad& b) {
    const double cosine = double(a.unit_normal[0]) * b.unit_normal[0] + double(a.unit_normal[1]) * b.unit_normal[1] +
                          double(a.unit_normal[2]) * b.unit_normal[2];
    return std::fabs(cosine) >= 0.866;
}

void widen_shared_sides(const float* corners, int n, OwnQuad* quads) {
    // Side s of a quad runs from corner s to corner s + 1: v = 0, u = 1, v = 1, u = 0.
    auto same_corner = [](const float* p, const float* q, double slack_m) {
        return std::fabs(double(p[0]) - q[0]) <= slack_m && std::fabs(double(p[1]) - q[1]) <= slack_m &&
               std::fabs(double(p[2]) - q[2]) <= slack_m;
    };
    for (int k = 0; k < n; ++k) {
        OwnQuad& q = quads[k];
        for (int side = 0; side < 4; ++side) {
            const float* a = corners + 12 * k + 3 * side;
            const float* b = corners + 12 * k + 3 * ((side + 1) % 4);
            bool shared = false;
            for (int j = 0; j < n && !shared; ++j) {
                if (j == k || !nearly_one_plane(q, quads[j])) continue;
                const double slack_m = std::fmax(q.slack_m, quads[j].slack_m);
                for (int other = 0; other < 4 && !shared; ++other) {
                    const float* c = corners + 12 * j + 3 * other;
                    const float* d = corners + 12 * j + 3 * ((other + 1) % 4);
                    shared = (same_corner(a, d, slack_m) && same_corner(b, c, slack_m)) ||
                             (same_corner(a, c, slack_m) && same_corner(b, d, slack_m));
                }
            }
            if (!shared) continue;
            const bool along_u = side == 1 || side == 3;  // the side bounds u
            const double m = along_u ? q.margin_u : q.margin_v;
            const double cap = m + std::fmin(m * kGrazeSlack / kShallowestGraze, 0.5);
            double* caps = along_u ? q.cap_u : q.cap_v;
            caps[side == 1 || side == 2 ? 1 : 0] = cap;  // sides 1 and 2 lie at u = 1 and v = 1
        }
    }
}

int max_own_quads() {
    constexpr int kMaxOwnQuads = 16;  // faces met; Embree level from 19 (quad_lanes.h)
    const char* text = std::getenv("LENSCOMPARE_MAX_OWN_QUADS");
    if (!text || !*text) return kMaxOwnQuads;
    char* end = nullptr;
    const long v = std::strtol(text, &end, 10);
    return (*end == '\0' && v >= 0 && v <= 1000000) ? int(v) : kMaxOwnQuads;
}

void quads_closest(SphereKernel kernel, const OwnQuad* quads, int n, const float* const origin[3],
                   const float* const direction[3], const int* active, float* t_far, int* index,
                   float* const normal[3], int* first_quad, uint64_t candidates) {
    switch (kernel) {
        case SphereKernel::Avx512:
            return closest_avx512(quads, n, origin, direction, active, t_far, index, normal, first_quad, candidates);
        case SphereKernel::Avx2:
            return closest_avx2(quads, n, origin, direction, active, t_far, index, normal, first_quad, candidates);
        default:
            return closest_default(quads, n, origin, direction, active, t_far, index, normal, first_quad, candidates);
    }
}

bool quads_occluded(SphereKernel kernel, const OwnQuad* quads, int n, const float* const origin[3],
                    const float* const direction[3], const float* t_far, const int* active, int* blocked,
                    uint64_t candidates) {
    switch (kernel) {
        case SphereKernel::Avx512:
            return occluded_avx512(quads, n, origin, direction, t_far, active, blocked, candidates);
        case SphereKernel::Avx2: return occluded_avx2(quads, n, origin, direction, t_far, active, blocked, candidates);
        default: return occluded_default(quads, n, origin, direction, t_far, active, blocked, candidates);
    }
}

}  // namespace lc
