#include "scene.h"

#include <algorithm>
#include <atomic>
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

namespace {

// The materials as shading_lanes.h's columns, the background as the last row.
MaterialColumns material_columns(const std::vector<Material>& materials, const Vec3f& background) {
    MaterialColumns t;
    auto add = [&t](const Vec3f& start, const Vec3f& color, const Vec3f& checker, float checker_size_m, bool diffuse) {
        const Vec3f* rows[3] = {&start, &color, &checker};
        std::vector<float>* columns[3] = {t.start, t.color, t.checker_color};
        for (int r = 0; r < 3; ++r) {
            columns[r][0].push_back(rows[r]->x), columns[r][1].push_back(rows[r]->y);
            columns[r][2].push_back(rows[r]->z);
        }
        t.checker_size_m.push_back(checker_size_m);
        t.diffuse.push_back(diffuse ? -1 : 0);
    };
    for (const Material& m : materials) {
        const bool diffuse = m.kind == MaterialKind::Diffuse;
        add(diffuse ? m.emission : m.color, m.color, m.checker_color, m.checker_size_m, diffuse);
    }
    add(background, Vec3f{}, Vec3f{}, 0.0f, false);
    return t;
}

bool is_zero(const float* v) { return v[0] == 0.0f && v[1] == 0.0f && v[2] == 0.0f; }

// Velocity of primitive i of an (n x 3) array, or zero when the array is absent.
Vec3f velocity_at(const float* velocities, size_t i) {
    return velocities ? Vec3f{velocities[3 * i], velocities[3 * i + 1], velocities[3 * i + 2]} : Vec3f{};
}

// Position p moved to time t (s): p + v t, per coordinate in float as Embree stores it.
void moved(const float* p, const Vec3f& v, double t_s, float* out) {
    out[0] = float(double(p[0]) + double(v.x) * t_s);
    out[1] = float(double(p[1]) + double(v.y) * t_s);
    out[2] = float(double(p[2]) + double(v.z) * t_s);
}

// One kind's primitives split by whether they move: each group becomes its own geometry.
struct Split {
    std::vector<size_t> still, moving;
};

Split split_by_velocity(const float* velocities, size_t n, bool split) {
    Split s;
    for (size_t i = 0; i < n; ++i)
        (split && velocities && !is_zero(velocities + 3 * i) ? s.moving : s.still).push_back(i);
    return s;
}

}  // namespace

Scene::Scene(const SceneArrays& a)
    : motion_(a.motion), materials_(a.materials), lights_(a.lights), background_(a.background) {
    static std::atomic<uint64_t> built{0};
    id_ = ++built;
    device_ = rtcNewDevice(embree_device_config());
    if (!device_) throw std::runtime_error("could not create an Embree device");
    scene_ = rtcNewScene(device_);
    // Robust mode keeps box edges watertight (no light leaking between quads).
    rtcSetSceneFlags(scene_, embree_edge_flags());
    rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);

    // Without a time per sample every primitive is a still one, at its place
    // when the shutter opens (t = 0 normally: then exactly the static scene,
    // one geometry per kind as always). With one, moving primitives get their
    // own geometries holding two time steps, open and close.
    const bool sampled = motion_.samples_time();
    const double open_s = motion_.open_s, close_s = motion_.close_s;
    const bool offset = open_s != 0.0;  // still primitives need moving to t = open
    const int steps = sampled ? 2 : 1;
    // Moving primitives go into a scene of their own (static geometries never
    // share one with motion-blurred ones), made when the first one comes.
    // Robust traversal only when it holds edges to keep watertight (quads,
    // triangles): spheres have none, and it costs time.
    auto target_of = [&](bool moving, bool edged) {
        if (moving && !motion_scene_) {
            motion_scene_ = rtcNewScene(device_);
            rtcSetSceneBuildQuality(motion_scene_, RTC_BUILD_QUALITY_HIGH);
        }
        if (moving && edged) rtcSetSceneFlags(motion_scene_, embree_edge_flags());
        return moving ? motion_scene_ : scene_;
    };

    // Spheres: Embree's sphere points are exact spheres, not tessellations.
    GeometryTable own_table;
    const Split spheres = split_by_velocity(a.sphere_velocity, size_t(a.n_spheres), sampled);
    for (int moving = 0; moving < 2; ++moving) {
        const std::vector<size_t>& ids = moving ? spheres.moving : spheres.still;
        if (ids.empty()) continue;
        GeometryTable table;
        for (size_t i : ids) {
            table.material.push_back(a.sphere_material[i]);
            if (a.sphere_velocity) table.velocity.push_back(velocity_at(a.sphere_velocity, i));
        }
        // A few still spheres: the render's own test (sphere_lanes.h), at the
        // place Embree would have had them.
        if (!moving && int(ids.size()) <= max_own_spheres()) {
            for (size_t i : ids) {
                const float* src = a.spheres + 4 * i;
                float centre[3] = {src[0], src[1], src[2]};
                if (offset) moved(src, velocity_at(a.sphere_velocity, i), open_s, centre);
                own_spheres_.insert(own_spheres_.end(), {centre[0], centre[1], centre[2], src[3]});
            }
            own_table = std::move(table);
            continue;
        }
        RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_SPHERE_POINT);
        const int slots = moving ? steps : 1;
        rtcSetGeometryTimeStepCount(g, unsigned(slots));
        for (int step = 0; step < slots; ++step) {
            auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, unsigned(step),
                                                                  RTC_FORMAT_FLOAT4, 4 * sizeof(float), ids.size()));
            const double t_s = step == 0 ? open_s : close_s;
            for (size_t k = 0; k < ids.size(); ++k) {
                const float* src = a.spheres + 4 * ids[k];
                if (moving || offset) moved(src, velocity_at(a.sphere_velocity, ids[k]), t_s, v + 4 * k);
                else std::copy(src, src + 3, v + 4 * k);
                v[4 * k + 3] = src[3];
            }
        }
        if (moving)
            for (size_t i : ids) {
                const Vec3f velocity = velocity_at(a.sphere_velocity, i);
                float centre_open[3], centre_close[3];
                moved(a.spheres + 4 * i, velocity, open_s, centre_open);
                moved(a.spheres + 4 * i, velocity, close_s, centre_close);
                movers_.add_sphere(velocity, centre_open, centre_close, a.spheres[4 * i + 3]);
            }
        attach(target_of(moving, false), g, std::move(table));
    }

    // Quads: four corners each.
    GeometryTable own_quad_table;
    const Split quads = split_by_velocity(a.quad_velocity, size_t(a.n_quads), sampled);
    for (int moving = 0; moving < 2; ++moving) {
        const std::vector<size_t>& ids = moving ? quads.moving : quads.still;
        if (ids.empty()) continue;
        // A few still parallelograms: the render's own test (quad_lanes.h), at
        // the place Embree would have had them; all of them or none.
        // The limit counts the faces a ray may meet: a box's three.
        std::vector<int32_t> solid(ids.size(), -1);
        if (a.quad_solid)
            for (size_t k = 0; k < ids.size(); ++k) solid[k] = a.quad_solid[ids[k]];
        if (!moving && ids.size() <= 64 && SolidFaces::faces_met(solid.data(), int(ids.size())) <= max_own_quads()) {
            std::vector<OwnQuad> own(ids.size());
            std::vector<float> corners(12 * ids.size());
            bool all_parallelograms = true;
            for (size_t k = 0; k < ids.size() && all_parallelograms; ++k) {
                for (size_t c = 0; c < 4; ++c) {
                    const float* src = a.quads + 12 * ids[k] + 3 * c;
                    float* to = &corners[12 * k + 3 * c];
                    if (offset) moved(src, velocity_at(a.quad_velocity, ids[k]), open_s, to);
                    else std::copy(src, src + 3, to);
                }
                all_parallelograms = make_own_quad(&corners[12 * k], &own[k]);
            }
            if (all_parallelograms) {
                widen_shared_sides(corners.data(), int(own.size()), own.data());
                own_quads_ = std::move(own);
                own_solids_ = SolidFaces(corners.data(), solid.data(), int(ids.size()));
                for (size_t i : ids) {
                    own_quad_table.material.push_back(a.quad_material[i]);
                    if (a.quad_velocity) own_quad_table.velocity.push_back(velocity_at(a.quad_velocity, i));
                }
                continue;
            }
        }
        RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_QUAD);
        const int slots = moving ? steps : 1;
        rtcSetGeometryTimeStepCount(g, unsigned(slots));
        for (int step = 0; step < slots; ++step) {
            auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, unsigned(step),
                                                                  RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                                  4 * ids.size()));
            const double t_s = step == 0 ? open_s : close_s;
            for (size_t k = 0; k < ids.size(); ++k) {
                const Vec3f velocity = velocity_at(a.quad_velocity, ids[k]);
                for (size_t c = 0; c < 4; ++c) {
                    const float* src = a.quads + 12 * ids[k] + 3 * c;
                    if (moving || offset) moved(src, velocity, t_s, v + 12 * k + 3 * c);
                    else std::copy(src, src + 3, v + 12 * k + 3 * c);
                    if (moving) movers_.add_vertex(velocity, v + 12 * k + 3 * c);
                }
            }
        }
        auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT4,
                                                                   4 * sizeof(unsigned), ids.size()));
        for (unsigned i = 0; i < 4u * unsigned(ids.size()); ++i) idx[i] = i;
        GeometryTable table;
        for (size_t i : ids) {
            table.material.push_back(a.quad_material[i]);
            if (a.quad_velocity) table.velocity.push_back(velocity_at(a.quad_velocity, i));
        }
        attach(target_of(moving, true), g, std::move(table));
    }

    // Triangles: a triangle moves when its first vertex does (a mesh moves as
    // one); each group takes the vertices it uses, renumbered.
    std::vector<float> tri_velocity;
    if (a.vertex_velocity)
        for (int t = 0; t < a.n_triangles; ++t) {
            const float* v = a.vertex_velocity + 3 * size_t(a.triangles[3 * t]);
            tri_velocity.insert(tri_velocity.end(), v, v + 3);
        }
    const Split triangles =
        split_by_velocity(a.vertex_velocity ? tri_velocity.data() : nullptr, size_t(a.n_triangles), sampled);
    for (int moving = 0; moving < 2; ++moving) {
        const std::vector<size_t>& ids = moving ? triangles.moving : triangles.still;
        if (ids.empty()) continue;
        // Every vertex when one group holds all triangles (the static scene's own buffer), else renumbered.
        const bool all = ids.size() == size_t(a.n_triangles);
        std::vector<int32_t> new_index(all ? 0 : size_t(a.n_vertices), -1);
        std::vector<size_t> vertices;
        if (all) {
            for (int i = 0; i < a.n_vertices; ++i) vertices.push_back(size_t(i));
        } else {
            for (size_t t : ids)
                for (int c = 0; c < 3; ++c) {
                    const size_t vi = size_t(a.triangles[3 * t + size_t(c)]);
                    if (new_index[vi] < 0) new_index[vi] = int32_t(vertices.size()), vertices.push_back(vi);
                }
        }
        RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
        const int slots = moving ? steps : 1;
        rtcSetGeometryTimeStepCount(g, unsigned(slots));
        for (int step = 0; step < slots; ++step) {
            auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, unsigned(step),
                                                                  RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                                  vertices.size()));
            const double t_s = step == 0 ? open_s : close_s;
            for (size_t k = 0; k < vertices.size(); ++k) {
                const float* src = a.triangle_vertices + 3 * vertices[k];
                if (moving || offset) moved(src, velocity_at(a.vertex_velocity, vertices[k]), t_s, v + 3 * k);
                else std::copy(src, src + 3, v + 3 * k);
                if (moving) movers_.add_vertex(velocity_at(a.vertex_velocity, vertices[k]), v + 3 * k);
            }
        }
        auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                   3 * sizeof(unsigned), ids.size()));
        GeometryTable table;
        for (size_t k = 0; k < ids.size(); ++k) {
            for (int c = 0; c < 3; ++c) {
                const size_t vi = size_t(a.triangles[3 * ids[k] + size_t(c)]);
                idx[3 * k + size_t(c)] = unsigned(all ? vi : size_t(new_index[vi]));
            }
            table.material.push_back(a.triangle_material[ids[k]]);
            if (a.vertex_velocity) table.velocity.push_back(velocity_at(tri_velocity.data(), ids[k]));
        }
        attach(target_of(moving, true), g, std::move(table));
    }
    // The own spheres' and quads' tables after every Embree geometry's: IDs Embree never gives.
    embree_still_ = !tables_.empty();
    auto own_id = [&](GeometryTable& table) {
        bool still = true;  // as attach: zero velocities are no motion
        for (const Vec3f& v : table.velocity) still = still && v.x == 0.0f && v.y == 0.0f && v.z == 0.0f;
        if (still) table.velocity.clear();
        const unsigned id = unsigned(tables_.size());
        tables_.push_back(std::move(table));
        if (id == RTC_INVALID_GEOMETRY_ID) throw std::runtime_error("too many geometries");
        return id;
    };
    culls_ = packet_cull_enabled();
    for (const PointLight& light : lights_) {
        const float light_m[3] = {light.position_m.x, light.position_m.y, light.position_m.z};
        const uint64_t blocking = own_solids_.blocking_toward(light_m);
        LightOccluders o;
        // Where each own quad k is in this light's list (bit j of quads), or 0.
        std::vector<uint64_t> list_bit(own_quads_.size(), 0);
        for (size_t k = 0; k < own_quads_.size(); ++k)
            if (is_candidate(blocking, int(k))) {
                if (o.quads.size() < 64) list_bit[k] = uint64_t(1) << o.quads.size();
                o.quads.push_back(own_quads_[k]);
            }
        for (size_t k = 0; k < own_quads_.size(); ++k) {
            // The light's signed distance from quad k's plane (along its normal, or
            // its outward normal when it is a solid's face), against a margin ten
            // times the shadow rays' lift off the surface (1e-4 of the coordinates'
            // size, surface_lanes): beyond it every lit lane is on the light's side.
            const OwnQuad& q = own_quads_[k];
            const double* outward = own_solids_.outward_of(int(k));
            double side_m = 0.0, size_m = 1.0;
            for (int a = 0; a < 3; ++a) {
                side_m += (double(light_m[a]) - q.v0[a]) * (outward ? outward[a] : double(q.unit_normal[a]));
                size_m = std::max({size_m, std::fabs(double(light_m[a])), std::fabs(q.v0[a]) + double(q.bound[3])});
            }
            const double margin_m = 1e-3 * size_m;
            const bool clear = std::fabs(side_m) > margin_m;
            uint64_t drop = clear ? list_bit[k] : 0;
            if (outward && side_m > margin_m) {
                const uint64_t mates = own_solids_.solid_mates(int(k));
                for (size_t j = 0; j < own_quads_.size() && j < 64; ++j)
                    if ((mates >> j) & 1u) drop |= list_bit[j];
            }
            o.own_plane_drop.push_back(drop);
        }
        o.columns = CullColumns::of_own(own_spheres_, o.quads);
        o.packet_cull = culls_ && o.columns.count() > 0 && o.columns.count() <= 64;
        for (size_t k = 0; k + 3 < own_spheres_.size(); k += 4) {
            const float* c = &own_spheres_[k];
            const double lx = double(light.position_m.x) - c[0], ly = double(light.position_m.y) - c[1],
                         lz = double(light.position_m.z) - c[2];
            const bool outside = lx * lx + ly * ly + lz * lz > double(c[3]) * double(c[3]);
            if (outside && k / 4 < 32) o.outside_bits |= uint32_t(1) << (k / 4);
            o.outside_sphere.push_back(outside);
        }
        light_occluders_.push_back(std::move(o));
    }
    if (!own_spheres_.empty()) own_spheres_id_ = own_id(own_table);
    if (!own_quads_.empty()) own_quads_id_ = own_id(own_quad_table);
    sphere_kernel_ = fastest_sphere_kernel();
    shading_kernel_ = shading_kernel();
    material_columns_ = material_columns(materials_, background_);
    for (const auto* tables : {&tables_, &motion_tables_})
        for (const GeometryTable& table : *tables) any_velocity_ = any_velocity_ || !table.velocity.empty();
    rtcCommitScene(scene_);
    if (motion_scene_) rtcCommitScene(motion_scene_);
    movers_.finish();
    throw_on_device_error(device_, "building the scene");
}

void Scene::attach(RTCScene target, RTCGeometry g, GeometryTable table) {
    rtcCommitGeometry(g);
    const unsigned id = rtcAttachGeometry(target, g);
    rtcReleaseGeometry(g);
    std::vector<GeometryTable>& tables = target == scene_ ? tables_ : motion_tables_;
    if (tables.size() <= id) tables.resize(id + 1);
    // A table of zero velocities is no motion at all: the checker is then read in place.
    bool still = true;
    for (const Vec3f& v : table.velocity) still = still && v.x == 0.0f && v.y == 0.0f && v.z == 0.0f;
    if (still) table.velocity.clear();
    tables[id] = std::move(table);
}

Scene::~Scene() {
    if (motion_scene_) rtcReleaseScene(motion_scene_);
    if (scene_) rtcReleaseScene(scene_);
    if (device_) rtcReleaseDevice(device_);
}

void Scene::radiance(const RayBatch& rays, Vec3f* out) const {
    CameraHits hits;
    trace_camera_rays(rays, hits);

    // Misses and emitters are final already; diffuse hits start from their emission.
    float rgb[3][kPacketSize];
    int material[kPacketSize];
    gather_surfaces(rays, hits, material, rgb);
    if (lights_.empty() || !any_diffuse(hits.surface)) {  // misses and emitters only: final already
        write_radiance(rays.count, rgb, out);
        return;
    }
    surface_lanes(shading_kernel_, hits.packet, hits.surface);

    // Shadow rays, one packet per light
    for (size_t l = 0; l < lights_.size(); ++l) {
        const PointLight& light = lights_[l];
        ShadowRays shadow;
        if (!trace_shadow_rays(l, hits, shadow)) continue;
        const float intensity[3] = {light.intensity.x, light.intensity.y, light.intensity.z};
        add_light_lanes(shading_kernel_, intensity, hits.surface, shadow.lanes, shadow.packet.tfar, rgb);
    }
    write_radiance(rays.count, rgb, out);
}

float Scene::first_hit_distance(const Vec3f& origin, const Vec3f& direction) const {
    RTCRayHit rh = intersect(scene_, origin, direction);
    float t = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? kInf : rh.ray.tfar;
    if (!own_spheres_.empty() || !own_quads_.empty()) {  // one lane of a packet of copies
        float lanes[6][kSphereLanes], n[3][kSphereLanes], t_far[kSphereLanes];
        int active[kSphereLanes] = {1}, index[kSphereLanes];
        for (int i = 0; i < kSphereLanes; ++i) {
            lanes[0][i] = origin.x, lanes[1][i] = origin.y, lanes[2][i] = origin.z;
            lanes[3][i] = direction.x, lanes[4][i] = direction.y, lanes[5][i] = direction.z;
            t_far[i] = t;
        }
        const float* o[3] = {lanes[0], lanes[1], lanes[2]};
        const float* d[3] = {lanes[3], lanes[4], lanes[5]};
        float* const normal[3] = {n[0], n[1], n[2]};
        if (!own_spheres_.empty())
            spheres_closest(sphere_kernel_, own_spheres_.data(), int(own_spheres_.size() / 4), o, d, active, t_far,
                            index, normal);
        if (!own_quads_.empty())
            quads_closest(sphere_kernel_, own_quads_.data(), int(own_quads_.size()), o, d, active, t_far, index,
                          normal);
        t = t_far[0];
    }
    if (motion_scene_) {
        RTCRayHit moving = intersect(motion_scene_, origin, direction);  // where movers are when the shutter opens
        if (moving.hit.geomID != RTC_INVALID_GEOMETRY_ID) t = std::min(t, moving.ray.tfar);
    }
    return t;
}

}  // namespace lc
