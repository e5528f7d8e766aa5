#include "scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace lc {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

void throw_on_device_error(RTCDevice device, const char* what) {
    RTCError err = rtcGetDeviceError(device);
    if (err != RTC_ERROR_NONE) throw std::runtime_error(std::string("Embree error while ") + what);
}

// Offset that lifts a shadow-ray origin off the surface it starts on, scaled
// with the coordinates because float spacing grows with them.
float surface_offset(const Vec3f& p) {
    float m = std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z), 1.0f});
    return 1e-4f * m;
}

// One closest-hit query; the hit's geomID is RTC_INVALID_GEOMETRY_ID on a miss.
RTCRayHit intersect(RTCScene scene, const Vec3f& origin, const Vec3f& direction) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh;
    rh.ray.org_x = origin.x, rh.ray.org_y = origin.y, rh.ray.org_z = origin.z;
    rh.ray.dir_x = direction.x, rh.ray.dir_y = direction.y, rh.ray.dir_z = direction.z;
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = kInf;
    rh.ray.time = 0.0f;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &context, &rh);
    return rh;
}

}  // namespace

bool checker_is_odd(const Vec3f& p_m, float size_m) {
    constexpr double kTolerance = 0.001;
    double sum = std::floor(double(p_m.x) / size_m + kTolerance) + std::floor(double(p_m.y) / size_m + kTolerance) +
                 std::floor(double(p_m.z) / size_m + kTolerance);
    return (int64_t(sum) & 1) != 0;
}

Scene::Scene(const SceneArrays& a)
    : materials_(a.materials), lights_(a.lights), background_(a.background) {
    device_ = rtcNewDevice(nullptr);
    if (!device_) throw std::runtime_error("could not create an Embree device");
    scene_ = rtcNewScene(device_);
    // Robust mode keeps box edges watertight (no light leaking between quads).
    rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);

    if (a.n_spheres > 0) {
        // Embree's sphere points are exact spheres, not tessellations.
        RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_SPHERE_POINT);
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                                              4 * sizeof(float), size_t(a.n_spheres)));
        std::copy(a.spheres, a.spheres + 4 * size_t(a.n_spheres), v);
        rtcCommitGeometry(g);
        sphere_geom_id_ = rtcAttachGeometry(scene_, g);
        rtcReleaseGeometry(g);
        sphere_material_.assign(a.sphere_material, a.sphere_material + a.n_spheres);
    }
    if (a.n_quads > 0) {
        RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_QUAD);
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                              3 * sizeof(float), 4 * size_t(a.n_quads)));
        std::copy(a.quads, a.quads + 12 * size_t(a.n_quads), v);
        auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT4,
                                                                   4 * sizeof(unsigned), size_t(a.n_quads)));
        for (unsigned i = 0; i < 4u * unsigned(a.n_quads); ++i) idx[i] = i;
        rtcCommitGeometry(g);
        rtcAttachGeometry(scene_, g);
        rtcReleaseGeometry(g);
        quad_material_.assign(a.quad_material, a.quad_material + a.n_quads);
    }
    if (a.n_triangles > 0) {
        RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                              3 * sizeof(float), size_t(a.n_vertices)));
        std::copy(a.triangle_vertices, a.triangle_vertices + 3 * size_t(a.n_vertices), v);
        auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                   3 * sizeof(unsigned), size_t(a.n_triangles)));
        std::copy(a.triangles, a.triangles + 3 * size_t(a.n_triangles), idx);
        rtcCommitGeometry(g);
        triangle_geom_id_ = rtcAttachGeometry(scene_, g);
        rtcReleaseGeometry(g);
        triangle_material_.assign(a.triangle_material, a.triangle_material + a.n_triangles);
    }
    rtcCommitScene(scene_);
    throw_on_device_error(device_, "building the scene");
}

Scene::~Scene() {
    if (scene_) rtcReleaseScene(scene_);
    if (device_) rtcReleaseDevice(device_);
}

const Material& Scene::material_of(unsigned geom_id, unsigned prim_id) const {
    int index = geom_id == sphere_geom_id_     ? sphere_material_[prim_id]
                : geom_id == triangle_geom_id_ ? triangle_material_[prim_id]
                                               : quad_material_[prim_id];
    return materials_[size_t(index)];
}

void Scene::radiance(const RayBatch& rays, Vec3f* out) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;

    // Camera rays
    alignas(32) int valid[kPacketSize];
    alignas(32) RTCRayHit8 hits;
    for (int i = 0; i < kPacketSize; ++i) {
        bool used = i < rays.count;
        valid[i] = used ? -1 : 0;
        Vec3f o = used ? rays.origin[i] : Vec3f{}, d = used ? rays.direction[i] : Vec3f{0, 0, 1};
        hits.ray.org_x[i] = o.x, hits.ray.org_y[i] = o.y, hits.ray.org_z[i] = o.z;
        hits.ray.dir_x[i] = d.x, hits.ray.dir_y[i] = d.y, hits.ray.dir_z[i] = d.z;
        hits.ray.tnear[i] = 0.0f;
        hits.ray.tfar[i] = kInf;
        hits.ray.time[i] = 0.0f;
        hits.ray.mask[i] = 0xFFFFFFFFu;
        hits.ray.id[i] = unsigned(i);
        hits.ray.flags[i] = 0;
        hits.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
        hits.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect8(valid, scene_, &context, &hits);

    // Surface points of the diffuse hits; misses and emitters are final already.
    bool diffuse[kPacketSize] = {};
    Vec3f p[kPacketSize], n[kPacketSize], albedo[kPacketSize];
    for (int i = 0; i < rays.count; ++i) {
        if (hits.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID) {
            out[i] = background_;
            continue;
        }
        const Material& m = material_of(hits.hit.geomID[i], hits.hit.primID[i]);
        if (m.kind == MaterialKind::Emissive) {
            out[i] = m.color;
            continue;
        }
        diffuse[i] = true;
        p[i] = rays.origin[i] + rays.direction[i] * hits.ray.tfar[i];
        n[i] = normalize(Vec3f{hits.hit.Ng_x[i], hits.hit.Ng_y[i], hits.hit.Ng_z[i]});
        if (dot(n[i], rays.direction[i]) > 0.0f) n[i] = -n[i];  // two-sided: shade the side the ray sees
        albedo[i] = (m.checker_size_m > 0.0f && checker_is_odd(p[i], m.checker_size_m)) ? m.checker_color : m.color;
        out[i] = m.emission;
    }

    // Shadow rays, one packet per light
    for (const PointLight& light : lights_) {
        alignas(32) int shadow_valid[kPacketSize];
        alignas(32) RTCRay8 shadow;
        float cos_theta[kPacketSize] = {};
        float falloff[kPacketSize] = {};  // 1, or 1 / d^2 from the lit point
        bool any = false;
        for (int i = 0; i < kPacketSize; ++i) {
            shadow_valid[i] = 0;
            if (i >= rays.count || !diffuse[i]) continue;
            Vec3f to_light = light.position_m - p[i];
            float to_light_m = length(to_light);
            cos_theta[i] = dot(n[i], to_light) / to_light_m;
            if (!(cos_theta[i] > 0.0f)) continue;  // light behind the surface (or degenerate)
            falloff[i] = light.inverse_square ? 1.0f / (to_light_m * to_light_m) : 1.0f;
            Vec3f from = p[i] + n[i] * surface_offset(p[i]);
            Vec3f d = light.position_m - from;
            float dist = length(d);
            shadow.org_x[i] = from.x, shadow.org_y[i] = from.y, shadow.org_z[i] = from.z;
            shadow.dir_x[i] = d.x / dist, shadow.dir_y[i] = d.y / dist, shadow.dir_z[i] = d.z / dist;
            shadow.tnear[i] = 0.0f;
            shadow.tfar[i] = dist * (1.0f - 1e-5f);
            shadow.time[i] = 0.0f;
            shadow.mask[i] = 0xFFFFFFFFu;
            shadow.id[i] = unsigned(i);
            shadow.flags[i] = 0;
            shadow_valid[i] = -1;
            any = true;
        }
        if (!any) continue;
        rtcOccluded8(shadow_valid, scene_, &context, &shadow);
        for (int i = 0; i < rays.count; ++i)
            if (shadow_valid[i] && shadow.tfar[i] != -kInf)
                out[i] += albedo[i] * light.intensity * (cos_theta[i] * falloff[i]);
    }
}

float Scene::first_hit_distance(const Vec3f& origin, const Vec3f& direction) const {
    RTCRayHit rh = intersect(scene_, origin, direction);
    return rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? kInf : rh.ray.tfar;
}

}  // namespace lc
