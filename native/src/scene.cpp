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
    rtcCommitScene(scene_);
    throw_on_device_error(device_, "building the scene");
}

Scene::~Scene() {
    if (scene_) rtcReleaseScene(scene_);
    if (device_) rtcReleaseDevice(device_);
}

bool Scene::occluded(const Vec3f& from, const Vec3f& to) const {
    Vec3f d = to - from;
    float dist = length(d);
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray;
    ray.org_x = from.x, ray.org_y = from.y, ray.org_z = from.z;
    ray.dir_x = d.x / dist, ray.dir_y = d.y / dist, ray.dir_z = d.z / dist;
    ray.tnear = 0.0f;
    ray.tfar = dist * (1.0f - 1e-5f);
    ray.time = 0.0f;
    ray.mask = 0xFFFFFFFFu;
    ray.id = 0;
    ray.flags = 0;
    rtcOccluded1(scene_, &context, &ray);
    return ray.tfar == -kInf;
}

Vec3f Scene::shade_diffuse(const Material& m, const Vec3f& p, const Vec3f& n) const {
    Vec3f albedo = (m.checker_size_m > 0.0f && checker_is_odd(p, m.checker_size_m)) ? m.checker_color : m.color;
    Vec3f result = m.emission;
    Vec3f p_lifted = p + n * surface_offset(p);
    for (const PointLight& light : lights_) {
        Vec3f to_light = light.position_m - p;
        float dist = length(to_light);
        float cos_theta = dot(n, to_light) / dist;
        if (!(cos_theta > 0.0f)) continue;  // light behind the surface (or degenerate)
        if (occluded(p_lifted, light.position_m)) continue;
        result += albedo * light.intensity * cos_theta;
    }
    return result;
}

Vec3f Scene::radiance(const Vec3d& origin, const Vec3d& direction) const {
    RTCRayHit rh = intersect(scene_, Vec3f(origin), Vec3f(direction));
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return background_;

    int material_index = rh.hit.geomID == sphere_geom_id_ ? sphere_material_[rh.hit.primID] : quad_material_[rh.hit.primID];
    const Material& m = materials_[size_t(material_index)];
    if (m.kind == MaterialKind::Emissive) return m.color;

    Vec3f dir{rh.ray.dir_x, rh.ray.dir_y, rh.ray.dir_z};
    Vec3f p = Vec3f{rh.ray.org_x, rh.ray.org_y, rh.ray.org_z} + dir * rh.ray.tfar;
    Vec3f n = normalize(Vec3f{rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z});
    if (dot(n, dir) > 0.0f) n = -n;  // two-sided: shade the side the ray sees
    return shade_diffuse(m, p, n);
}

float Scene::first_hit_distance(const Vec3f& origin, const Vec3f& direction) const {
    RTCRayHit rh = intersect(scene_, origin, direction);
    return rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? kInf : rh.ray.tfar;
}

}  // namespace lc
