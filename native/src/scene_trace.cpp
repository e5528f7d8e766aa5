// The stages of shading both radiance paths share (scene.cpp for RGB,
// scene_spectral.cpp for spectral renders): camera rays to their hits, a
// diffuse hit's surface, and the shadow rays toward one light. Each path then
// only says what colour a hit, the background and a light contribute.
// Rays go to Embree as packets (embree_packet.h); a moving scene's geometry
// lives in a scene of its own, traced only by the rays that pass its bounds.
// The per-packet stages are built per instruction set (LC_BUILT_PER_ISA,
// cpu_kernels.h): their lane loops then run 16 wide on AVX-512 (4-6 % of a
// lit_showcase render), with the same bits.
#include <algorithm>
#include <cmath>
#include <limits>

#include "cpu_kernels.h"
#include "near_line_lanes.h"
#include "scene.h"

namespace lc {
namespace {

static_assert(SweptBounds::kLanes == kPacketSize, "the swept-bounds test takes one packet of rays");

constexpr float kInf = std::numeric_limits<float>::infinity();

}  // namespace

LC_BUILT_PER_ISA void Scene::trace_camera_rays(const RayBatch& rays, CameraHits& hits) const {
    RTCIntersectContext& context = hits.context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    alignas(kPacketAlignment) int valid[kPacketSize];
    RTCRayHitPacket& packet = hits.packet;
    hits.stream = rays.stream;
    // Whole rows copied, then idle lanes (past count: only a tile's last
    // packet has them) given a harmless ray.
    for (int i = 0; i < kPacketSize; ++i) {
        packet.ray.org_x[i] = rays.origin[0][i], packet.ray.org_y[i] = rays.origin[1][i];
        packet.ray.org_z[i] = rays.origin[2][i];
        packet.ray.dir_x[i] = rays.direction[0][i], packet.ray.dir_y[i] = rays.direction[1][i];
        packet.ray.dir_z[i] = rays.direction[2][i];
        packet.ray.time[i] = rays.time[i];
    }
    for (int i = rays.count; i < kPacketSize; ++i) {
        packet.ray.org_x[i] = packet.ray.org_y[i] = packet.ray.org_z[i] = 0.0f;
        packet.ray.dir_x[i] = packet.ray.dir_y[i] = 0.0f, packet.ray.dir_z[i] = 1.0f;
        packet.ray.time[i] = 0.0f;
    }
    for (int i = 0; i < kPacketSize; ++i) {
        valid[i] = i < rays.count ? -1 : 0;
        packet.ray.tnear[i] = 0.0f;
        packet.ray.tfar[i] = kInf;
        packet.ray.mask[i] = 0xFFFFFFFFu;
        packet.ray.id[i] = unsigned(i);
        packet.ray.flags[i] = 0;
        packet.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
        packet.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    // The own spheres first, then the own quads: their hits shorten the rays
    // Embree then traces, and each test (and Embree) replaces a hit only by a nearer one.
    const float* origin[3] = {packet.ray.org_x, packet.ray.org_y, packet.ray.org_z};
    const float* direction[3] = {packet.ray.dir_x, packet.ray.dir_y, packet.ray.dir_z};
    int index[kPacketSize];
    float ng[3][kPacketSize] = {};  // read by the selects below on every lane, hit or not
    float* const normal[3] = {ng[0], ng[1], ng[2]};
    // Selects on every lane (an idle one has index -1), so that the loop runs
    // lanes side by side. The first own geometry writes every lane (a lane it
    // did not hit as a miss), the next keeps what it did not hit.
    bool recorded = false;
    auto record_hits = [&](unsigned geometry) {
        RTCHit16& hit = packet.hit;
        if (!recorded) {
            for (int i = 0; i < kPacketSize; ++i) {
                const bool met = index[i] >= 0;
                hit.geomID[i] = met ? geometry : RTC_INVALID_GEOMETRY_ID;
                hit.primID[i] = met ? unsigned(index[i]) : 0u;
                hit.Ng_x[i] = met ? ng[0][i] : 0.0f, hit.Ng_y[i] = met ? ng[1][i] : 0.0f;
                hit.Ng_z[i] = met ? ng[2][i] : 0.0f;
                hit.u[i] = hit.v[i] = 0.0f;
            }
            recorded = true;
            return;
        }
        for (int i = 0; i < kPacketSize; ++i) {
            const bool met = index[i] >= 0;
            hit.geomID[i] = met ? geometry : hit.geomID[i];
            hit.primID[i] = met ? unsigned(index[i]) : hit.primID[i];
            hit.Ng_x[i] = met ? ng[0][i] : hit.Ng_x[i], hit.Ng_y[i] = met ? ng[1][i] : hit.Ng_y[i];
            hit.Ng_z[i] = met ? ng[2][i] : hit.Ng_z[i];
        }
    };
    if (!own_spheres_.empty()) {
        spheres_closest(sphere_kernel_, own_spheres_.data(), int(own_spheres_.size() / 4), origin, direction, valid,
                        packet.ray.tfar, index, normal, rays.sphere_candidates);
        record_hits(own_spheres_id_);
    }
    if (!own_quads_.empty()) {
        // The quad the thread's last packet met is tested first (any order
        // gives the same hits: quads_closest).
        thread_local int first_quad[RayBatch::kStreams] = {};
        // Boxes' faces the packet's origins are behind: never a first hit (solid_faces.h).
        thread_local OriginRegion region[RayBatch::kStreams];
        const uint64_t candidates =
            rays.faces_culled ? rays.quad_candidates
                              : own_solids_.first_hits_from(origin, valid, &region[rays.stream]) & rays.quad_candidates;
        quads_closest(sphere_kernel_, own_quads_.data(), int(own_quads_.size()), origin, direction, valid,
                      packet.ray.tfar, index, normal, &first_quad[rays.stream], candidates);
        record_hits(own_quads_id_);
    }
    if (embree_still_) intersect_packet(valid, scene_, &context, &packet);
    if (motion_scene_) intersect_movers(rays, context, packet, hits.hit_mover);
}

void Scene::camera_candidates(const CameraPencil& pencil, RayBatch* batch) const {
    if (!culls_) return;
    uint64_t spheres = kAllCandidates, quads = kAllCandidates;
    const int n_spheres = int(own_spheres_.size() / 4);
    for (int k = 0; k < std::min(n_spheres, 64); ++k)
        if (!pencil.may_meet_ball(&own_spheres_[4 * size_t(k)], own_spheres_[4 * size_t(k) + 3]))
            spheres &= ~(uint64_t(1) << k);
    for (int k = 0; k < std::min(int(own_quads_.size()), 64); ++k)
        if (!pencil.may_meet_ball(own_quads_[size_t(k)].bound, own_quads_[size_t(k)].bound[3]))
            quads &= ~(uint64_t(1) << k);
    // The boxes' faces the whole aperture is behind (solid_faces.h): the
    // lens disk's box, widened far past the origins' float rounding.
    if (!own_solids_.empty() && pencil.origins_on_lens_disk) {
        // (A moving camera's: the disk's box over its sweep.)
        const Frame& f = pencil.world_from_camera;
        const Vec3d mid = f.origin + pencil.sweep_mid_m;
        const double centre[3] = {mid.x, mid.y, mid.z};
        const double right[3] = {f.right.x, f.right.y, f.right.z}, up[3] = {f.up.x, f.up.y, f.up.z};
        const double margin_m = 1e-6 * (std::fabs(centre[0]) + std::fabs(centre[1]) + std::fabs(centre[2]) +
                                         pencil.lens_radius_m + pencil.sweep_half_m);
        double lo[3], hi[3];
        for (int a = 0; a < 3; ++a) {
            const double reach = pencil.lens_radius_m * std::sqrt(right[a] * right[a] + up[a] * up[a]) +
                                 pencil.sweep_half_m + margin_m;
            lo[a] = centre[a] - reach, hi[a] = centre[a] + reach;
        }
        quads &= own_solids_.first_hits_from_box(lo, hi);
    } else if (!own_solids_.empty() && pencil.origins_in_box) {
        quads &= own_solids_.first_hits_from_box(pencil.origins_lo_m, pencil.origins_hi_m);
    }
    batch->sphere_candidates = spheres, batch->quad_candidates = quads;
    batch->faces_culled = pencil.origins_on_lens_disk || pencil.origins_in_box || own_solids_.empty();
}

LC_BUILT_PER_ISA void Scene::write_radiance(int count, const float (&rgb)[3][kPacketSize], Vec3f* out) {
    for (int i = 0; i < count; ++i) out[i] = {rgb[0][i], rgb[1][i], rgb[2][i]};
}

int Scene::material_of(const CameraHits& hits, int i) const {
    const GeometryTable& table = (hits.hit_mover[i] ? motion_tables_ : tables_)[hits.packet.hit.geomID[i]];
    return table.material[hits.packet.hit.primID[i]];
}

LC_BUILT_PER_ISA void Scene::gather_surfaces(const RayBatch& rays, CameraHits& hits, int* material,
                            float (&rgb)[3][kPacketSize]) const {
    const int miss = material_columns_.miss();
    for (int i = 0; i < kPacketSize; ++i)
        material[i] = i < rays.count && !hits.missed(i) ? material_of(hits, i) : miss;
    SurfaceLanes& s = hits.surface;
    gather_lanes(shading_kernel_, material_columns_, material, s, rgb);
    for (int i = 0; i < kPacketSize; ++i) s.moving[i] = 0, s.shift_m[0][i] = s.shift_m[1][i] = s.shift_m[2][i] = 0.0f;
    if (!any_velocity_) return;
    // A moving object carries its checker: read it where the point was at t = 0.
    for (int i = 0; i < rays.count; ++i) {
        if (!s.diffuse[i]) continue;
        const GeometryTable& table = (hits.hit_mover[i] ? motion_tables_ : tables_)[hits.packet.hit.geomID[i]];
        if (table.velocity.empty()) continue;
        const Vec3f shift = table.velocity[hits.packet.hit.primID[i]] * float(motion_.time_s(rays.time[i]));
        s.moving[i] = -1;
        s.shift_m[0][i] = shift.x, s.shift_m[1][i] = shift.y, s.shift_m[2][i] = shift.z;
    }
}

LC_BUILT_PER_ISA bool Scene::trace_shadow_rays(size_t light_index, CameraHits& hits, ShadowRays& shadow) const {
    const PointLight& light = lights_[light_index];
    const float light_m[3] = {light.position_m.x, light.position_m.y, light.position_m.z};
    RTCRayPacket& packet = shadow.packet;
    const bool any = shadow_lanes(shading_kernel_, light_m, light.inverse_square, hits.surface, hits.packet.ray.time,
                                  shadow.lanes, packet);
    if (!any) return false;
    const int* valid = shadow.lanes.valid;
    RTCIntersectContext& context = hits.context;
    const LightOccluders& occluders = light_occluders_[light_index];
    const int n_spheres = int(own_spheres_.size() / 4);
    // From an own sphere's surface: it blocks the ray exactly when the ray
    // leaves its inner side toward a light outside it. Branch-free, so that
    // the lanes run side by side (per lane with branches, this loop was half
    // of this function, perf). self_blocked: some lane may be so blocked (one
    // starts on a sphere's inner side, found once per camera packet, not ORed
    // over the lanes per light); the sphere test reads each lane's self_blocks.
    bool self_blocked = false;
    if (n_spheres > 0) {
        if (!hits.starts_found) sphere_starts(hits);
        const int* start = hits.start_sphere;
        // The bits up to 32 spheres (the default cap); past that
        // (LENSCOMPARE_MAX_OWN_SPHERES) the flags, looked up per lane. The
        // look-up for every count was measured 3.5 % slower per sample.
        if (n_spheres <= 32) {
            const uint32_t outside = occluders.outside_bits;
            for (int i = 0; i < kPacketSize; ++i) {
                const int on_sphere = (valid[i] != 0) & (start[i] >= 0) & (hits.inner_side[i] != 0);
                shadow.self_blocks[i] = on_sphere & int((outside >> (start[i] & 31)) & 1u);
            }
        } else {
            for (int i = 0; i < kPacketSize; ++i) {
                shadow.self_blocks[i] = (valid[i] != 0) && start[i] >= 0 && hits.inner_side[i] != 0 &&
                                        occluders.outside_sphere[size_t(start[i])] != 0;
            }
        }
        self_blocked = hits.any_inner_start;
    }
    // The own quads that may block this light (not the boxes' faces it is behind: solid_faces.h).
    const std::vector<OwnQuad>& quads = occluders.quads;
    // The own primitives some lane's segment may reach (packet_bounds.h); the
    // rest are not tested. Without the cull every primitive is a candidate.
    uint64_t near_spheres = kAllCandidates, near_quads = kAllCandidates;
    if (occluders.packet_cull) {
        thread_local ShadowCullCache caches[RayBatch::kStreams];
        ShadowCullCache& cache = caches[hits.stream];
        if (!hits.cull_ball_taken) cache.take(id_, hits.surface), hits.cull_ball_taken = true;
        const uint64_t near =
            light_index < size_t(ShadowCullCache::kLights)
                ? cache.near(hits.surface, int(light_index), light_m, shading_kernel_, occluders.columns)
                : near_capsule(shading_kernel_, capsule_toward(hits.surface, light_m), occluders.columns);
        near_spheres = n_spheres == 64 ? near : near & ((uint64_t(1) << n_spheres) - 1);
        near_quads = n_spheres == 64 ? 0 : near >> n_spheres;
    }
    // Lanes all on one own primitive (SinglePrimitive): the sphere never
    // blocks them (spheres_occluded leaves a lane's start sphere to its
    // self_blocks); the quad does not when the light is clear of its plane,
    // nor do the other faces of its solid when the light is in front of it
    // (Scene::LightOccluders::own_plane_drop). Off with the packet cull
    // (LENSCOMPARE_PACKET_CULL=0), so that the tests can compare the two.
    if (culls_) {
        if (!hits.single_found) single_own_primitive(hits);
        if (hits.single.sphere >= 0 && hits.single.sphere < 64) near_spheres &= ~(uint64_t(1) << hits.single.sphere);
        if (hits.single.quad >= 0 && !quads.empty()) near_quads &= ~occluders.own_plane_drop[size_t(hits.single.quad)];
    }
    alignas(kPacketAlignment) int open[kPacketSize];  // lanes no own sphere or quad blocks
    for (int i = 0; i < kPacketSize; ++i) open[i] = valid[i];
    const float* origin[3] = {packet.org_x, packet.org_y, packet.org_z};
    const float* direction[3] = {packet.dir_x, packet.dir_y, packet.dir_z};
    // Blocked lanes get tfar -inf, as Embree marks them; returns whether any lane is left open.
    // Called only when the kernel blocked some lane: otherwise every open
    // lane stays open, and the OR over the lanes (a chain of shuffles) is not needed.
    auto close_blocked = [&](const int* blocked) {
        int left = 0;
        for (int i = 0; i < kPacketSize; ++i) {
            if (blocked[i]) packet.tfar[i] = -kInf;
            open[i] = open[i] && !blocked[i] ? -1 : 0;
            left |= open[i];
        }
        return left != 0;
    };
    bool any_open = true;
    if (n_spheres > 0 && (near_spheres != 0 || self_blocked)) {
        int blocked[kPacketSize];
        if (spheres_occluded(sphere_kernel_, own_spheres_.data(), n_spheres, origin, direction, packet.tfar,
                             hits.start_sphere, shadow.self_blocks, open, blocked, near_spheres))
            any_open = close_blocked(blocked);
    }
    if (any_open && !quads.empty() && near_quads != 0) {
        int blocked[kPacketSize];
        if (quads_occluded(sphere_kernel_, quads.data(), int(quads.size()), origin, direction, packet.tfar, open,
                           blocked, near_quads))
            any_open = close_blocked(blocked);
    }
    if (embree_still_ && any_open) occluded_packet(open, scene_, &context, &packet);
    if (motion_scene_) occlude_by_movers(valid, context, packet);
    return true;
}

namespace {

// Scene::sphere_starts' lanes, per instruction set. Returns whether some lane
// starts on an own sphere's inner side.
template <class Set>
[[gnu::always_inline]] inline bool sphere_starts_body(Set set, const float (&n)[3][kPacketSize], const RTCHit16& hit,
                                                      const bool* hit_mover, unsigned spheres_id,
                                                      int* __restrict start_sphere, int* __restrict inner_side) {
    // The flags widened first: with a bool load in the loop below GCC tried
    // only byte-sized vector modes and found none for the floats.
    alignas(64) int mover[kPacketSize], both[kPacketSize];
    lanes::widen_flags(set, hit_mover, mover);
    for (int i = 0; i < kPacketSize; ++i) {
        // A mover's geometry ID indexes the motion tables: never an own sphere.
        const int on_sphere = int(mover[i] == 0) & int(hit.geomID[i] == spheres_id);
        // As dot(n, ng) < 0, term by term: the same bits.
        const int inner = n[0][i] * hit.Ng_x[i] + n[1][i] * hit.Ng_y[i] + n[2][i] * hit.Ng_z[i] < 0.0f;
        start_sphere[i] = on_sphere ? int(hit.primID[i]) : -1;
        inner_side[i] = inner;
        both[i] = on_sphere & inner;
    }
    return lanes::any_set<kPacketSize>(set, both);
}

bool sphere_starts_default(const float (&n)[3][kPacketSize], const RTCHit16& hit, const bool* hit_mover,
                           unsigned spheres_id, int* start_sphere, int* inner_side) {
    return sphere_starts_body(lanes::PortableSet{}, n, hit, hit_mover, spheres_id, start_sphere, inner_side);
}
[[gnu::target("avx2")]] bool sphere_starts_avx2(const float (&n)[3][kPacketSize], const RTCHit16& hit,
                                                const bool* hit_mover, unsigned spheres_id, int* start_sphere,
                                                int* inner_side) {
    return sphere_starts_body(lanes::Avx2Set{}, n, hit, hit_mover, spheres_id, start_sphere, inner_side);
}
[[gnu::target("avx512f")]] bool sphere_starts_avx512(const float (&n)[3][kPacketSize], const RTCHit16& hit,
                                                     const bool* hit_mover, unsigned spheres_id, int* start_sphere,
                                                     int* inner_side) {
    return sphere_starts_body(lanes::Avx512Set{}, n, hit, hit_mover, spheres_id, start_sphere, inner_side);
}

}  // namespace

void Scene::sphere_starts(CameraHits& hits) const {
    // Built per instruction set on the shading kernel: as target_clones GCC
    // left the lane loop scalar with branches, and the OR of the lanes then
    // reloaded its sixteen narrow stores as one wide load, which waited on
    // them (perf: 3 % of a peers_lit render).
    const auto starts = shading_kernel_ == ShadingKernel::Avx512 ? sphere_starts_avx512
                        : shading_kernel_ == ShadingKernel::Avx2 ? sphere_starts_avx2
                                                                 : sphere_starts_default;
    hits.any_inner_start = starts(hits.surface.n, hits.packet.hit, hits.hit_mover, own_spheres_id_,
                                  hits.start_sphere, hits.inner_side);
    hits.starts_found = true;
}

namespace {

// Scene::single_own_primitive's lanes, per instruction set: the own sphere
// or quad every diffuse lane met (geometry spheres_id or quads_id), if one.
template <class Set>
[[gnu::always_inline]] inline SinglePrimitive single_primitive_body(Set set, const int* diffuse, const RTCHit16& hit,
                                                                    const bool* hit_mover, unsigned spheres_id,
                                                                    unsigned quads_id) {
    SinglePrimitive single;
    int first = 0;
    while (first < kPacketSize - 1 && diffuse[first] == 0) ++first;
    if (diffuse[first] == 0 || hit_mover[first]) return single;
    const unsigned geometry = hit.geomID[first], primitive = hit.primID[first];
    if (geometry != quads_id && geometry != spheres_id) return single;
    alignas(64) int mover[kPacketSize], elsewhere[kPacketSize];
    lanes::widen_flags(set, hit_mover, mover);
    for (int i = 0; i < kPacketSize; ++i) {
        const int on = int(mover[i] == 0) & int(hit.geomID[i] == geometry) & int(hit.primID[i] == primitive);
        elsewhere[i] = -(int(diffuse[i] != 0) & (on ^ 1));
    }
    if (lanes::any_set<kPacketSize>(set, elsewhere)) return single;
    (geometry == quads_id ? single.quad : single.sphere) = int(primitive);
    return single;
}

SinglePrimitive single_primitive_default(const int* diffuse, const RTCHit16& hit, const bool* hit_mover,
                                         unsigned spheres_id, unsigned quads_id) {
    return single_primitive_body(lanes::PortableSet{}, diffuse, hit, hit_mover, spheres_id, quads_id);
}
[[gnu::target("avx2")]] SinglePrimitive single_primitive_avx2(const int* diffuse, const RTCHit16& hit,
                                                              const bool* hit_mover, unsigned spheres_id,
                                                              unsigned quads_id) {
    return single_primitive_body(lanes::Avx2Set{}, diffuse, hit, hit_mover, spheres_id, quads_id);
}
[[gnu::target("avx512f")]] SinglePrimitive single_primitive_avx512(const int* diffuse, const RTCHit16& hit,
                                                                   const bool* hit_mover, unsigned spheres_id,
                                                                   unsigned quads_id) {
    return single_primitive_body(lanes::Avx512Set{}, diffuse, hit, hit_mover, spheres_id, quads_id);
}

}  // namespace

void Scene::single_own_primitive(CameraHits& hits) const {
    // Per instruction set on the shading kernel, as sphere_starts (a scalar
    // loop over the lanes was 13 instructions a sample of peers_lit).
    const auto single = shading_kernel_ == ShadingKernel::Avx512 ? single_primitive_avx512
                        : shading_kernel_ == ShadingKernel::Avx2 ? single_primitive_avx2
                                                                 : single_primitive_default;
    hits.single = single(hits.surface.diffuse, hits.packet.hit, hits.hit_mover, own_spheres_id_, own_quads_id_);
    hits.single_found = true;
}

// The moving geometry for the rays of the packet that pass through its swept
// bounds before their hit so far: a nearer hit replaces the static one, and
// hit_mover says whose tables its geometry ID indexes.
void Scene::intersect_movers(const RayBatch& rays, RTCIntersectContext& context, RTCRayHitPacket& hits,
                             bool* hit_mover) const {
    alignas(kPacketAlignment) int valid[kPacketSize];
    int active[kPacketSize];
    for (int i = 0; i < kPacketSize; ++i) active[i] = i < rays.count;
    const float* origin[3] = {hits.ray.org_x, hits.ray.org_y, hits.ray.org_z};
    const float* direction[3] = {hits.ray.dir_x, hits.ray.dir_y, hits.ray.dir_z};
    if (!movers_.may_hit(origin, direction, hits.ray.tfar, hits.ray.time, active, valid)) return;
    // The static hit, kept aside: Embree writes the hit only when it finds a nearer one.
    unsigned geom[kPacketSize], prim[kPacketSize];
    float ng[kPacketSize][3];
    for (int i = 0; i < rays.count; ++i) {
        geom[i] = hits.hit.geomID[i], prim[i] = hits.hit.primID[i];
        ng[i][0] = hits.hit.Ng_x[i], ng[i][1] = hits.hit.Ng_y[i], ng[i][2] = hits.hit.Ng_z[i];
        if (valid[i]) hits.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
    }
    intersect_packet(valid, motion_scene_, &context, &hits);
    for (int i = 0; i < rays.count; ++i) {
        if (!valid[i]) continue;
        hit_mover[i] = hits.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID;
        if (hit_mover[i]) continue;
        hits.hit.geomID[i] = geom[i], hits.hit.primID[i] = prim[i];
        hits.hit.Ng_x[i] = ng[i][0], hits.hit.Ng_y[i] = ng[i][1], hits.hit.Ng_z[i] = ng[i][2];
    }
}

// Shadow rays that no still geometry blocks, against the moving geometry
// where their segment passes through its swept bounds.
void Scene::occlude_by_movers(const int* shadow_valid, RTCIntersectContext& context, RTCRayPacket& shadow) const {
    // Only rays no still geometry blocks (Embree sets tfar to -inf on a blocked one).
    int active[kPacketSize];
    for (int i = 0; i < kPacketSize; ++i) active[i] = shadow_valid[i] && shadow.tfar[i] != -kInf;
    const float* origin[3] = {shadow.org_x, shadow.org_y, shadow.org_z};
    const float* direction[3] = {shadow.dir_x, shadow.dir_y, shadow.dir_z};
    alignas(kPacketAlignment) int valid[kPacketSize];
    if (movers_.may_hit(origin, direction, shadow.tfar, shadow.time, active, valid))
        occluded_packet(valid, motion_scene_, &context, &shadow);
}

}  // namespace lc
