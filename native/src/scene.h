// The scene as Embree sees it, plus the shading the contract fixes: emissive
// surfaces, Lambert diffuse lit by point lights with hard shadows and, per
// light, no distance falloff (POV-Ray's default) or inverse-square falloff
// (Mitsuba's and pbrt's point light), background colour for misses.
// Objects may move during the shutter (motion.h): moving primitives go into
// geometries with two time steps in an Embree scene of their own, static ones
// stay in the static scene, so a scene where one sphere moves keeps the
// static BVH for everything else, and only rays that pass through the movers'
// swept bounds pay for a second traversal.
#pragma once

#include <embree3/rtcore.h>

#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "embree_packet.h"
#include "motion.h"
#include "packet_bounds.h"
#include "quad_lanes.h"
#include "shading_lanes.h"
#include "solid_faces.h"
#include "sphere_lanes.h"
#include "spectral.h"
#include "spectral_bands.h"
#include "cameras/camera_pencil.h"
#include "cameras/camera_ray.h"
#include "vec.h"

namespace lc {

enum class MaterialKind : int { Emissive = 0, Diffuse = 1 };

struct Material {
    MaterialKind kind;
    Vec3f color;          // emissive radiance, or diffuse albedo
    Vec3f emission;       // added to the lit diffuse result
    Vec3f checker_color;  // albedo of the odd checker cubes
    float checker_size_m; // 0: no checker
};

// In columns (x, y, z rows of lanes), as Embree's packets and the own
// primitives' tests take them: the packet is filled by copying rows.
struct RayBatch {
    int count = 0;  // rays in use, <= kPacketSize
    float origin[3][kPacketSize] = {};
    float direction[3][kPacketSize] = {};
    float time[kPacketSize] = {};  // where in the shutter, [0, 1) (Embree's ray time); 0 for a static scene
    // The own spheres and quads the rays may meet (is_candidate): a tile's
    // camera rays skip those its pencil cannot reach (Scene::camera_candidates).
    uint64_t sphere_candidates = kAllCandidates, quad_candidates = kAllCandidates;
    bool faces_culled = false;  // quad_candidates leaves out the boxes' faces the origins are behind
    // Which of a thread's interleaved packet streams these rays are (the
    // lens system's mirror images, render_mirrored.h: four pixels a quarter
    // of the image apart, their packets shaded in turn), each with its own
    // per-thread caches of what the packets before it found (the boxes'
    // faces a region of origins sees, the shadow cull's ball): one cache for
    // all four was replaced at every packet. Any stream gives the same bits.
    static constexpr int kStreams = 4;
    int stream = 0;  // [0, kStreams)

    // The rays test every own primitive again (their tile's cull no longer holds).
    void uncull() { sphere_candidates = quad_candidates = kAllCandidates, faces_culled = false; }

    // Ray j = a camera ray, rounded to float.
    void set(int j, const CameraRay& ray) {
        origin[0][j] = float(ray.origin.x), origin[1][j] = float(ray.origin.y), origin[2][j] = float(ray.origin.z);
        direction[0][j] = float(ray.direction.x), direction[1][j] = float(ray.direction.y),
        direction[2][j] = float(ray.direction.z);
    }

    // Ray j = ray i of a camera batch's float rows.
    void set(int j, const CameraRayRows& rows, int i) {
        for (int a = 0; a < 3; ++a) origin[a][j] = rows.origin[a][i], direction[a][j] = rows.direction[a][i];
    }
};

struct PointLight {
    Vec3f position_m;
    Vec3f intensity;             // radiant intensity
    bool inverse_square = false;  // divide by the squared distance (m^2) to the lit point
};

// Flat arrays in the layout Python hands over (C-contiguous float32/int32).
struct SceneArrays {
    const float* spheres = nullptr;  // n_spheres x 4: centre xyz, radius (m)
    const int32_t* sphere_material = nullptr;
    int n_spheres = 0;
    const float* quads = nullptr;    // n_quads x 4 corners x 3 (m), corners in order round the quad
    const int32_t* quad_material = nullptr;
    const int32_t* quad_solid = nullptr;  // per quad, the box it is a face of, or -1; nullptr: no boxes
    int n_quads = 0;
    const float* triangle_vertices = nullptr;  // n_vertices x 3 (m): the meshes' vertices, all meshes in one
    int n_vertices = 0;
    const int32_t* triangles = nullptr;        // n_triangles x 3 vertex indices
    const int32_t* triangle_material = nullptr;
    int n_triangles = 0;
    // Velocities (m/s), one per sphere, per quad and per mesh vertex; nullptr: nothing of that kind moves.
    const float* sphere_velocity = nullptr;
    const float* quad_velocity = nullptr;
    const float* vertex_velocity = nullptr;
    SceneMotion motion;
    std::vector<Material> materials;
    std::vector<PointLight> lights;
    Vec3f background;
};

// The one own primitive a camera packet's diffuse lanes are all on, if one
// (Scene::single_own_primitive): its shadow rays need not test it.
struct SinglePrimitive {
    int sphere = -1, quad = -1;  // its index, or -1
};

class Scene {
  public:
    explicit Scene(const SceneArrays& arrays);
    ~Scene();
    Scene(const Scene&) = delete;
    Scene& operator=(const Scene&) = delete;

    // Radiance arriving along up to kPacketSize rays (origins in m, unit
    // directions): the one function the render loop calls. Rays go to Embree
    // as packets (embree_packet.h), camera rays and shadow rays alike, which traces
    // coherent rays faster than one at a time.
    void radiance(const RayBatch& rays, Vec3f* radiance_out) const;

    // Spectral renders (scene_spectral.cpp): radiance at each ray's four
    // wavelengths (ray i's: *wavelengths[i], in its lanes), the scene's
    // colours taken to spectra by the basis there.
    void spectral_radiance(const RayBatch& rays, const HeroWavelengths* const* wavelengths,
                           float (*radiance_out)[kHeroWavelengths]) const;

    // Spectral renders through a camera that does not disperse: the film's
    // reading of each ray's spectrum integrated over the wavelengths, exactly
    // (spectral.h, integrate_still), as linear sRGB.
    void spectral_integrated_radiance(const RayBatch& rays, Vec3f* radiance_out) const;

    // Spectral renders through a dispersive thin or thick lens
    // (render_tile_bands.h): the same, each ray's spectrum integrated over
    // the wavelengths it carries, those of its band of planes of focus
    // (spectral_bands.h; bands null: every ray the whole spectrum,
    // spectral_integrated_radiance).
    void spectral_band_radiance(const RayBatch& rays, const RayFocusBands* bands, Vec3f* radiance_out) const;
    // The band integrals those renders read, for a lens whose 1 / focus per
    // nm is inverse_focus_per_m_by_nm (after set_spectral).
    FocusBandIntegrals focus_band_integrals(const std::vector<double>& inverse_focus_per_m_by_nm) const;

    // Set once, before rendering: the scene then renders spectrally.
    void set_spectral(std::shared_ptr<const SpectralTables> tables);
    const SpectralTables* spectral() const { return spectral_.get(); }
    size_t material_count() const { return materials_.size(); }

    // Nearest hit distance (m) or +inf; used by the raw-throughput benchmark.
    float first_hit_distance(const Vec3f& origin, const Vec3f& direction) const;


    // The own spheres and quads some ray of the pencil may meet (bit k:
    // primitive k, as is_candidate reads it), into a batch's candidates.
    void camera_candidates(const CameraPencil& pencil, RayBatch* batch) const;

    // The shutter and what moves; the render loop draws sample times from it.
    const SceneMotion& motion() const { return motion_; }

  private:
    // What shading needs of each primitive of one Embree geometry.
    struct GeometryTable {
        std::vector<int32_t> material;
        std::vector<Vec3f> velocity;  // empty: the geometry does not move
    };

    void attach(RTCScene target, RTCGeometry geometry, GeometryTable table);

    // The stages radiance and spectral_radiance share (scene_trace.cpp), so
    // that both see the same hits, surfaces and shadows.
    struct CameraHits {  // one packet of camera rays, traced, and its diffuse hits
        RTCIntersectContext context;  // coherent rays; shadow rays reuse it
        alignas(kPacketAlignment) RTCRayHitPacket packet;
        bool hit_mover[kPacketSize] = {};  // whose tables the hit's geometry ID indexes
        SurfaceLanes surface;              // gathered by gather_surfaces, found by surface_lanes
        // For the shadow rays, found once per camera packet, by its first
        // light's shadow packet (sphere_starts):
        // the own sphere each lane's hit is on (-1: none), and whether the
        // hit is on its inner side (the shading normal turned to face the camera).
        bool starts_found = false;
        int start_sphere[kPacketSize];
        int inner_side[kPacketSize];
        bool any_inner_start = false;  // some lane's start sphere and inner side both set
        // The own primitive every diffuse lane's hit is on, if one; found
        // when the first light's shadow packet asks (single_own_primitive).
        bool single_found = false;
        SinglePrimitive single;
        bool cull_ball_taken = false;  // the thread's ShadowCullCache has this packet's ball
        int stream = 0;                // the rays' RayBatch::stream: whose caches
        bool missed(int i) const { return packet.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID; }
    };
    struct ShadowRays {  // one packet of shadow rays toward one light, traced
        ShadowLanes lanes;  // valid, cos_theta, falloff
        alignas(kPacketAlignment) RTCRayPacket packet;
        int self_blocks[kPacketSize];     // the sphere it starts on blocks it (from inside toward a light outside)
        // traced and not blocked (Embree's tfar of -inf)
        bool lit(int i) const { return lanes.valid[i] && packet.tfar[i] != -std::numeric_limits<float>::infinity(); }
    };
    void trace_camera_rays(const RayBatch& rays, CameraHits& hits) const;
    // Lanes [0, count) of rgb, the packet's radiance, into out one ray each.
    static void write_radiance(int count, const float (&rgb)[3][kPacketSize], Vec3f* out);
    // The material index of hit i (not a miss).
    int material_of(const CameraHits& hits, int i) const;
    // Each lane's material row (material_columns_'s miss row for a miss or an
    // idle lane), and what surface_lanes needs of it and of the hit's motion;
    // rgb gets each lane's radiance before any light.
    void gather_surfaces(const RayBatch& rays, CameraHits& hits, int* material, float (&rgb)[3][kPacketSize]) const;
    // Shadow rays from the diffuse hits (surface_lanes done) toward lights_[light], traced; false when none was needed.
    bool trace_shadow_rays(size_t light, CameraHits& hits, ShadowRays& shadow) const;
    // hits' start_sphere and inner_side, once per camera packet (the same for every light).
    void sphere_starts(CameraHits& hits) const;
    // hits.single, once per camera packet.
    void single_own_primitive(CameraHits& hits) const;
    // Whether lane i of hits shows a monochromatic emitter (spectral renders: its line alone).
    bool shows_line(const CameraHits& hits, const int* material, int i) const {
        return !hits.missed(i) && materials_[size_t(material[i])].kind == MaterialKind::Emissive &&
               spectral_->has_line(material[i]);
    }
    void intersect_movers(const RayBatch& rays, RTCIntersectContext& context, RTCRayHitPacket& hits,
                          bool* hit_mover) const;
    void occlude_by_movers(const int* shadow_valid, RTCIntersectContext& context, RTCRayPacket& shadow) const;

    RTCDevice device_ = nullptr;
    RTCScene scene_ = nullptr;         // still geometry
    RTCScene motion_scene_ = nullptr;  // moving geometry, two time steps; nullptr when nothing moves
    std::vector<GeometryTable> tables_, motion_tables_;  // by Embree geometry ID in scene_, motion_scene_
    // Still spheres the render tests itself (sphere_lanes.h): centre xyz, radius (m) each;
    // their hits carry geometry ID own_spheres_id_ (a table of tables_ that Embree never uses).
    std::vector<float> own_spheres_;
    unsigned own_spheres_id_ = RTC_INVALID_GEOMETRY_ID;
    // Still quads the render tests itself (quad_lanes.h), all or none; their hits carry own_quads_id_.
    std::vector<OwnQuad> own_quads_;
    unsigned own_quads_id_ = RTC_INVALID_GEOMETRY_ID;
    SolidFaces own_solids_;  // the own quads' boxes, whose hidden faces camera rays skip
    // Per light, what its shadow rays test besides the own spheres: the own
    // quads that may block them (not a box's faces the light is behind:
    // solid_faces.h), and the spheres and those quads as the per-packet cull
    // takes them (packet_bounds.h).
    struct LightOccluders {
        std::vector<OwnQuad> quads;
        CullColumns columns;
        bool packet_cull = false;
        // Per own sphere, whether the light is outside it (a ray from its
        // inner side toward the light is then blocked by it); the first 32
        // also as bits, which lanes read without a gather.
        std::vector<int> outside_sphere;
        uint32_t outside_bits = 0;
        // Per own quad k, the bits of quads that cannot block the shadow rays
        // of lanes on k, when the light is clear of k's plane by a margin
        // (else 0): a lit lane is then on the light's side of the plane and so
        // is its segment, which cannot cross k; when k is a face of a solid and
        // the light in front of it, the segment stays outside the solid, and
        // none of the solid's faces can block it.
        std::vector<uint64_t> own_plane_drop;
    };
    std::vector<LightOccluders> light_occluders_;
    uint64_t id_ = 0;  // unique in the process (ShadowCullCache: whose candidates a thread keeps)
    SphereKernel sphere_kernel_ = SphereKernel::Default;
    ShadingKernel shading_kernel_ = ShadingKernel::Default;  // shading_lanes.h
    bool embree_still_ = false;  // scene_ holds geometry
    // packet_cull_enabled, read once when built: the shadow packets' cull
    // (LightOccluders::packet_cull) and the camera tiles' (camera_candidates).
    bool culls_ = false;
    SweptBounds movers_;               // where motion_scene_'s geometry can be during the shutter
    SceneMotion motion_;
    std::vector<Material> materials_;
    MaterialColumns material_columns_;  // materials_ and the background, for gather_lanes
    bool any_velocity_ = false;         // some geometry table has velocities
    std::vector<PointLight> lights_;
    Vec3f background_;
    std::shared_ptr<const SpectralTables> spectral_;
    // Per light, the film's reading of it off a basis colour (SpectralTables::film_of_light).
    struct FilmMap {
        float of_basis[3][3];
    };
    std::vector<FilmMap> film_of_lights_;
};

// Checker: parity of floor(p/size + 0.001) summed over the axes; even -> the
// first colour. The tolerance (POV-Ray 3.6's; 3.7 uses 1e-10) keeps a floor at
// y = 0 on one side despite float32 hit points; the POV-Ray export shifts its
// checker by 0.001 cubes so that both renderers agree.
bool checker_is_odd(const Vec3f& p_m, float size_m);

}  // namespace lc
