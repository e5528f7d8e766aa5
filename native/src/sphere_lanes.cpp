#include "sphere_lanes.h"

#include "cpu_kernels.h"
#include "near_line_lanes.h"

#include <cmath>
#include <cstdlib>
#include <cstring>

namespace lc {
namespace {

constexpr int N = kSphereLanes;

// Lane loops without branches, written once and compiled per instruction set
// (the always_inline bodies below, called from functions with a target
// attribute), so that GCC runs the lanes side by side in each.

// Both roots t_lo <= t_hi of lane i's line with sphere c, in double; NaN
// where the line misses (a negative discriminant) or is degenerate.
struct Roots {
    double lo[N], hi[N];
};

[[gnu::always_inline]] inline void roots(const float* c, const lanes::DoubleLanes<N>& ray, Roots& out) {
    const double cx = c[0], cy = c[1], cz = c[2], r = c[3], r2 = r * r;
    for (int i = 0; i < N; ++i) {
        const double dx = ray.d[0][i], dy = ray.d[1][i], dz = ray.d[2][i];
        // f = o - centre: exact in double for floats of any likely scale
        const double fx = ray.o[0][i] - cx, fy = ray.o[1][i] - cy, fz = ray.o[2][i] - cz;
        const double a = dx * dx + dy * dy + dz * dz;
        const double b = fx * dx + fy * dy + fz * dz;  // half the quadratic's b
        const double s = b / a;
        // Haines et al. eq. 7.5: b^2 - ac = a (r^2 - |f - (b/a) d|^2), free of b^2's cancellation
        const double px = fx - s * dx, py = fy - s * dy, pz = fz - s * dz;
        const double disc = r2 - (px * px + py * py + pz * pz);
        const double cc = (fx * fx + fy * fy + fz * fz) - r2;
        const double root = std::sqrt(disc >= 0.0 ? a * disc : -1.0);  // NaN on a miss
        // q = -(b + sign(b) sqrt(a disc)): adds like signs, so no cancellation (eq. 7.7)
        const double q = -(b + (b < 0.0 ? -root : root));
        const double t0 = q / a, t1 = cc / q;  // 0/0 (a tangent through the origin) is NaN: a miss
        out.lo[i] = t0 < t1 ? t0 : t1;
        out.hi[i] = t0 < t1 ? t1 : t0;
        // NaN in either root: both NaN, so no comparison accepts the lane
        const bool bad = !(t0 == t0) | !(t1 == t1);
        out.lo[i] = bad ? NAN : out.lo[i];
        out.hi[i] = bad ? NAN : out.hi[i];
    }
}

template <class Set>
[[gnu::always_inline]] inline void closest_body(Set set, const float* spheres, int n, const float* const origin[3],
                                                const float* const direction[3], const int* active, float* t_far,
                                                int* index, float* const normal[3], uint64_t candidates) {
    float inv_dd[N], origin_size[N];
    lanes::lane_scales<N>(origin, direction, inv_dd, origin_size);
    lanes::DoubleLanes<N> ray;
    double t_best[N] = {};
    for (int i = 0; i < N; ++i) index[i] = -1;
    for (int k = 0; k < n; ++k) {
        if (!is_candidate(candidates, k)) continue;
        const float* c = spheres + 4 * k;
        if (!lanes::near_line<N>(set, c, origin, direction, inv_dd, origin_size, active)) continue;
        ray.load_once(origin, direction);
        Roots t;
        roots(c, ray, t);
        for (int i = 0; i < N; ++i) {
            // The nearer root in front of the origin, else the farther (a ray from inside)
            const double hit = t.lo[i] >= 0.0 ? t.lo[i] : t.hi[i];
            const float hit_f = float(hit);
            // Strictly nearer: of two spheres at one distance the first keeps the hit
            const bool take = (active[i] != 0) & (hit >= 0.0) & (hit_f < t_far[i]);
            t_far[i] = take ? hit_f : t_far[i];
            t_best[i] = take ? hit : t_best[i];
            index[i] = take ? k : index[i];
        }
    }
    if (!ray.loaded) return;  // no sphere near any lane: no hit, so no normal to find
    // Outward normals, (f + t d) / r, from the double hit distance
    for (int i = 0; i < N; ++i) {
        const int k = index[i] < 0 ? 0 : index[i];
        const float* c = spheres + 4 * k;
        const double t = index[i] < 0 ? 0.0 : t_best[i];
        const double inv_r = 1.0 / double(c[3]);
        for (int a = 0; a < 3; ++a)
            normal[a][i] = float((ray.o[a][i] - double(c[a]) + t * ray.d[a][i]) * inv_r);
    }
}

template <class Set>
[[gnu::always_inline]] inline bool occluded_body(Set set, const float* spheres, int n, const float* const origin[3],
                                                 const float* const direction[3], const float* t_far,
                                                 const int* start_sphere, const int* self_blocks, const int* active,
                                                 int* blocked, uint64_t candidates) {
    float inv_dd[N], origin_size[N];
    lanes::lane_scales<N>(origin, direction, inv_dd, origin_size);
    lanes::DoubleLanes<N> ray;
    int met[N] = {};
    for (int k = 0; k < n; ++k) {
        if (!is_candidate(candidates, k)) continue;
        const float* c = spheres + 4 * k;
        if (!lanes::near_line<N>(set, c, origin, direction, inv_dd, origin_size, active)) continue;
        ray.load_once(origin, direction);
        Roots t;
        roots(c, ray, t);
        for (int i = 0; i < N; ++i) {
            const double far = t_far[i];
            // A root on the segment: the surface crosses it
            const bool crossed = ((t.lo[i] >= 0.0) & (t.lo[i] <= far)) | ((t.hi[i] >= 0.0) & (t.hi[i] <= far));
            met[i] |= (start_sphere[i] != k) & crossed;
        }
    }
    // The sphere a lane starts on blocks it whatever the line test said
    for (int i = 0; i < N; ++i) met[i] |= (start_sphere[i] >= 0) & (start_sphere[i] < n) & (self_blocks[i] != 0);
    for (int i = 0; i < N; ++i) blocked[i] = (active[i] != 0) & (met[i] != 0) ? -1 : 0;
    return lanes::any_set<N>(set, blocked);
}

void closest_default(const float* s, int n, const float* const o[3], const float* const d[3], const int* active,
                     float* t_far, int* index, float* const normal[3], uint64_t candidates) {
    closest_body(lanes::PortableSet{}, s, n, o, d, active, t_far, index, normal, candidates);
}
[[gnu::target("avx2")]] void closest_avx2(const float* s, int n, const float* const o[3], const float* const d[3],
                                          const int* active, float* t_far, int* index, float* const normal[3],
                                          uint64_t candidates) {
    closest_body(lanes::Avx2Set{}, s, n, o, d, active, t_far, index, normal, candidates);
}
[[gnu::target("avx512f")]] void closest_avx512(const float* s, int n, const float* const o[3],
                                               const float* const d[3], const int* active, float* t_far, int* index,
                                               float* const normal[3], uint64_t candidates) {
    closest_body(lanes::Avx512Set{}, s, n, o, d, active, t_far, index, normal, candidates);
}

bool occluded_default(const float* s, int n, const float* const o[3], const float* const d[3], const float* t_far,
                      const int* start, const int* self, const int* active, int* blocked, uint64_t candidates) {
    return occluded_body(lanes::PortableSet{}, s, n, o, d, t_far, start, self, active, blocked, candidates);
}
[[gnu::target("avx2")]] bool occluded_avx2(const float* s, int n, const float* const o[3], const float* const d[3],
                                           const float* t_far, const int* start, const int* self, const int* active,
                                           int* blocked, uint64_t candidates) {
    return occluded_body(lanes::Avx2Set{}, s, n, o, d, t_far, start, self, active, blocked, candidates);
}
[[gnu::target("avx512f")]] bool occluded_avx512(const float* s, int n, const float* const o[3],
                                                const float* const d[3], const float* t_far, const int* start,
                                                const int* self, const int* active, int* blocked,
                                                uint64_t candidates) {
    return occluded_body(lanes::Avx512Set{}, s, n, o, d, t_far, start, self, active, blocked, candidates);
}

}  // namespace

bool sphere_kernel_available(SphereKernel kernel) {
    switch (kernel) {
        case SphereKernel::Avx2: return __builtin_cpu_supports("avx2");
        case SphereKernel::Avx512: return __builtin_cpu_supports("avx512f");
        default: return true;
    }
}

const char* sphere_kernel_name(SphereKernel kernel) {
    switch (kernel) {
        case SphereKernel::Avx2: return "avx2";
        case SphereKernel::Avx512: return "avx512";
        default: return "default";
    }
}

SphereKernel fastest_sphere_kernel() {
    static const SphereKernel best = fastest_available(kSphereKernels, sphere_kernel_available);
    return best;
}

int max_own_spheres() {
    constexpr int kMaxOwnSpheres = 32;  // Embree ahead past some 40 (sphere_lanes.h)
    const char* text = std::getenv("LENSCOMPARE_MAX_OWN_SPHERES");
    if (!text || !*text) return kMaxOwnSpheres;
    char* end = nullptr;
    const long v = std::strtol(text, &end, 10);
    return (*end == '\0' && v >= 0 && v <= 1000000) ? int(v) : kMaxOwnSpheres;
}

void spheres_closest(SphereKernel kernel, const float* spheres, int n, const float* const origin[3],
                     const float* const direction[3], const int* active, float* t_far, int* index,
                     float* const normal[3], uint64_t candidates) {
    switch (kernel) {
        case SphereKernel::Avx512:
            return closest_avx512(spheres, n, origin, direction, active, t_far, index, normal, candidates);
        case SphereKernel::Avx2:
            return closest_avx2(spheres, n, origin, direction, active, t_far, index, normal, candidates);
        default: return closest_default(spheres, n, origin, direction, active, t_far, index, normal, candidates);
    }
}

bool spheres_occluded(SphereKernel kernel, const float* spheres, int n, const float* const origin[3],
                      const float* const direction[3], const float* t_far, const int* start_sphere,
                      const int* self_blocks, const int* active, int* blocked, uint64_t candidates) {
    switch (kernel) {
        case SphereKernel::Avx512:
            return occluded_avx512(spheres, n, origin, direction, t_far, start_sphere, self_blocks, active, blocked,
                                   candidates);
        case SphereKernel::Avx2:
            return occluded_avx2(spheres, n, origin, direction, t_far, start_sphere, self_blocks, active, blocked,
                                 candidates);
        default:
            return occluded_default(spheres, n, origin, direction, t_far, start_sphere, self_blocks, active, blocked,
                                    candidates);
    }
}

}  // namespace lc
