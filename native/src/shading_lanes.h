// The arithmetic of shading one packet, lane by lane without branches (SoA):
// the diffuse hits' points, normals and albedo, the shadow rays toward one
// light, and each lit lane's share of that light. Per ray in scalar code,
// with a branch per lane, this set-up cost as much as Embree's shadow query
// (perf on showcase: trace_shadow_rays 10.8 % of the render, occluded 4.7 %).
// Only what needs Embree's geometry tables stays per lane (scene_trace.cpp:
// each hit's material row, a mover's shift); these kernels run the lanes
// side by side, compiled once per instruction set (as sphere_lanes.cpp).
// Every kernel gives the same bits as the scalar code it replaced: the same
// correctly rounded operations in the same order, no fused multiply-adds
// (CMakeLists.txt), and selects where that code skipped a lane.
#pragma once

#include <vector>

#include "embree_packet.h"

namespace lc {

// The instruction set the kernels below run with: the CPU's best, or
// LENSCOMPARE_SHADING_KERNEL's choice (default, avx2, avx512) where the CPU
// can run it, so that tests can compare the images of each. Read once.
enum class ShadingKernel : int { Default = 0, Avx2 = 1, Avx512 = 2 };
ShadingKernel shading_kernel();
const char* shading_kernel_name(ShadingKernel kernel);

// The scene's materials as columns, one row each plus a last row for a miss
// (the background), so that a packet's lanes gather theirs side by side.
struct MaterialColumns {
    std::vector<float> start[3];  // radiance before any light: an emitter's colour, a diffuse emission, the background
    std::vector<float> color[3];  // albedo, and the odd checker cubes' albedo
    std::vector<float> checker_color[3];
    std::vector<float> checker_size_m;  // 0: no checker
    std::vector<int> diffuse;           // -1: diffuse
    int miss() const { return int(diffuse.size()) - 1; }
};

// One packet's diffuse hits: what gather_lanes fills, and what surface_lanes finds.
struct SurfaceLanes {
    // Gathered from the lanes' materials
    alignas(kPacketAlignment) int diffuse[kPacketSize];  // -1: a diffuse hit
    float color[3][kPacketSize];
    float checker_color[3][kPacketSize];
    float checker_size_m[kPacketSize];
    // Set per lane, only where the hit object moves (zero elsewhere): the
    // checker is read where the point was at t = 0.
    // (Zeroed by Scene::gather_surfaces, not here: as member initialisers
    // GCC zeroed them by a rep stos per camera packet, a third of
    // Scene::radiance's own time under perf.)
    int moving[kPacketSize];          // -1: the hit object moves
    float shift_m[3][kPacketSize];    // velocity x shutter time: how far it moved since t = 0
    // Found by surface_lanes
    float p[3][kPacketSize];       // point (m)
    float n[3][kPacketSize];       // unit normal facing the ray
    float albedo[3][kPacketSize];
    float from_m[3][kPacketSize];  // where its shadow rays start: p lifted off the surface along n
    // A ball round the diffuse lanes' from_m (centre the first one's; radius
    // infinite if any is not finite): one bound for every light's shadow
    // packet (capsule_toward, packet_bounds.h) instead of one per light.
    float from_centre_m[3], from_radius_m;
};

// Where a shadow segment stops, as a fraction of the way from its origin to
// its light (shadow_lanes' rays are not normalised): 1e-5 of the distance short.
constexpr float kShadowEnd = 1.0f - 1e-5f;

// Lane i takes row material[i] of table (its miss row for a miss or an idle
// lane): its inputs into s, its radiance before any light into rgb.
void gather_lanes(ShadingKernel kernel, const MaterialColumns& table, const int* material, SurfaceLanes& s,
                  float (&rgb)[3][kPacketSize]);

// Point, normal (two-sided: the side the ray sees) and albedo of every
// diffuse lane, from the traced camera packet (its origins, directions, hit
// distances and geometric normals).
void surface_lanes(ShadingKernel kernel, const RTCRayHitPacket& camera, SurfaceLanes& s);

// Whether any lane gathered a diffuse hit: a packet of misses and emitters
// (sky, lamps) is final after gather_lanes, with no surface or light to find.
inline bool any_diffuse(const SurfaceLanes& s) {
    int any = 0;
    for (int i = 0; i < kPacketSize; ++i) any |= s.diffuse[i];
    return any != 0;
}

// One packet of shadow rays from the diffuse lanes toward a point light.
struct ShadowLanes {
    alignas(kPacketAlignment) int valid[kPacketSize];  // -1: traced (a diffuse hit facing the light)
    float cos_theta[kPacketSize];  // at the surface; used only where valid
    float falloff[kPacketSize];    // 1, or 1 / d^2 from the lit point
};

// Fills shadow (and packet's rays, idle lanes with a harmless ray) for the
// light at light_m; time[i] is each camera ray's shutter time, which its
// shadow ray keeps. Returns whether any lane is valid.
bool shadow_lanes(ShadingKernel kernel, const float light_m[3], bool inverse_square, const SurfaceLanes& s,
                  const float* time, ShadowLanes& shadow, RTCRayPacket& packet);

// rgb += albedo x intensity x (cos_theta x falloff) on the lanes the light
// reaches: valid and not blocked (Embree's tfar of -inf).
void add_light_lanes(ShadingKernel kernel, const float intensity[3], const SurfaceLanes& s,
                     const ShadowLanes& shadow, const float* shadow_tfar, float (&rgb)[3][kPacketSize]);

// out = m in, lane by lane (a colour through a 3 x 3 map: spectral.h's
// integrals for a spectral render through a camera that does not disperse).
void map_colour_lanes(ShadingKernel kernel, const float (&m)[3][3], const float (&in)[3][kPacketSize],
                      float (&out)[3][kPacketSize]);

}  // namespace lc
