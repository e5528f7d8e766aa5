// Still spheres the render intersects itself, a packet of rays at a time,
// instead of handing them to Embree: Embree keeps sphere points in its curve
// BVH, whose packet test cost lit_showcase's 5 spheres a third of the render
// (0.38 of 1.13 CPU s; ours 0.06). A test per sphere per ray grows with their
// count: on a floor of n spheres (bench/bench_spheres.py) it was 6 % ahead
// of Embree at n = 32, 3 % behind at 48, so past 32 Embree keeps them.
//
// The test itself follows Haines, Günther and Akenine-Möller, "Precision
// Improvements for Ray/Sphere Intersection", Ray Tracing Gems (2019), ch. 7:
// the discriminant from the ray's perpendicular distance to the centre, and
// the nearer root as c / q so that neither root cancels. It runs in double
// (the float origin and centre subtract exactly), so grazing rays, huge and
// tiny spheres keep their hits; a float test culls the spheres no lane of
// the packet comes near first.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace lc {

// The kernels (one instruction set each) give the same bits: no fused
// multiply-adds (CMakeLists.txt), only correctly rounded operations.
enum class SphereKernel : int { Default = 0, Avx2 = 1, Avx512 = 2 };
constexpr SphereKernel kSphereKernels[] = {SphereKernel::Default, SphereKernel::Avx2, SphereKernel::Avx512};
bool sphere_kernel_available(SphereKernel kernel);
const char* sphere_kernel_name(SphereKernel kernel);
SphereKernel fastest_sphere_kernel();

// Which primitives of a call a packet may meet: bit k for primitive k < 64,
// those past 64 always. A cull outside the kernels (packet_bounds.h) clears
// the bits of primitives no lane can reach.
constexpr uint64_t kAllCandidates = ~uint64_t(0);
inline bool is_candidate(uint64_t candidates, int k) { return k >= 64 || ((candidates >> k) & 1u) != 0; }

// f(k) for each candidate k < n but skip, in increasing order: the set bits
// of the first 64, then every k from 64.
template <class F>
[[gnu::always_inline]] inline void for_each_candidate(uint64_t candidates, int n, int skip, F&& f) {
    uint64_t bits = n >= 64 ? candidates : candidates & ((uint64_t(1) << n) - 1);
    if (skip >= 0 && skip < 64) bits &= ~(uint64_t(1) << skip);
    for (; bits != 0; bits &= bits - 1) f(__builtin_ctzll(bits));
    for (int k = 64; k < n; ++k)
        if (k != skip) f(k);
}

// How many rays one call takes: the render's packet width (embree_packet.h).
constexpr int kSphereLanes = 16;

// The largest count of still spheres the render intersects itself (32); more go to
// Embree. LENSCOMPARE_MAX_OWN_SPHERES overrides it (0: Embree takes all),
// for tests and benchmarks that compare the two.
int max_own_spheres();

// Closest hits of kSphereLanes rays (SoA origins, directions, m) with n
// spheres (centre xyz, radius, m, each) at t in [0, t_far[i]): where lane i
// (active[i] set) meets a sphere nearer than t_far[i], t_far[i] becomes the
// hit distance, index[i] the sphere and normal[.][i] its outward unit
// normal there; other lanes keep t_far and get index -1. Only the spheres
// candidates names are tested (is_candidate).
void spheres_closest(SphereKernel kernel, const float* spheres, int n, const float* const origin[3],
                     const float* const direction[3], const int* active, float* t_far, int* index,
                     float* const normal[3], uint64_t candidates = kAllCandidates);

// Whether the segments t in [0, t_far[i]] cross some sphere's surface:
// blocked[i] = -1 where so (active lanes), else 0. A ray that starts on a
// sphere's surface (start_sphere[i] >= 0) is not asked about that sphere: a
// sphere blocks a segment from its own surface exactly when the segment goes
// inside and ends outside, which the caller knows (self_blocks[i]); a
// rounded root near t = 0 would shadow the surface itself.
// Only the spheres candidates names are tested (is_candidate: a caller that
// knows no lane comes near sphere k clears its bit). Returns whether any lane is blocked.
bool spheres_occluded(SphereKernel kernel, const float* spheres, int n, const float* const origin[3],
                      const float* const direction[3], const float* t_far, const int* start_sphere,
                      const int* self_blocks, const int* active, int* blocked,
                      uint64_t candidates = kAllCandidates);

}  // namespace lc
