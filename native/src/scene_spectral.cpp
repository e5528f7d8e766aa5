// Scene::radiance for spectral renders: the same shading (emitters, Lambert
// diffuse lit by point lights with hard shadows, background for misses), each
// RGB colour of the file taken to a spectrum by the Mallett–Yuksel 2019 basis
// and evaluated at the ray's wavelengths (spectral.h). Kept apart from
// scene.cpp so that the RGB path is untouched, bit for bit and in speed.
#include <algorithm>
#include <cmath>
#include <limits>

#include "scene.h"

namespace lc {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNearestFalloffM2 = 1e-8f;  // as scene.cpp

float surface_offset(const Vec3f& p) {  // as scene.cpp
    float m = std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z), 1.0f});
    return 1e-4f * m;
}

}  // namespace

void Scene::spectral_radiance(const RayBatch& rays, const float (*wavelengths_nm)[kHeroWavelengths],
                              const Vec3f (*basis)[kHeroWavelengths], int n_wavelengths,
                              float (*out)[kHeroWavelengths]) const {
    const SpectralTables& spectra = *spectral_;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;

    // Camera rays
    alignas(kPacketAlignment) int valid[kPacketSize];
    alignas(kPacketAlignment) RTCRayHitPacket hits;
    for (int i = 0; i < kPacketSize; ++i) {
        bool used = i < rays.count;
        valid[i] = used ? -1 : 0;
        Vec3f o = used ? rays.origin[i] : Vec3f{}, d = used ? rays.direction[i] : Vec3f{0, 0, 1};
        hits.ray.org_x[i] = o.x, hits.ray.org_y[i] = o.y, hits.ray.org_z[i] = o.z;
        hits.ray.dir_x[i] = d.x, hits.ray.dir_y[i] = d.y, hits.ray.dir_z[i] = d.z;
        hits.ray.tnear[i] = 0.0f;
        hits.ray.tfar[i] = kInf;
        hits.ray.time[i] = used ? rays.time[i] : 0.0f;
        hits.ray.mask[i] = 0xFFFFFFFFu;
        hits.ray.id[i] = unsigned(i);
        hits.ray.flags[i] = 0;
        hits.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
        hits.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    intersect_packet(valid, scene_, &context, &hits);

    // A colour c is dot(c, basis) at each ray's wavelengths.
    bool diffuse[kPacketSize] = {};
    Vec3f p[kPacketSize], n[kPacketSize], albedo[kPacketSize];
    for (int i = 0; i < rays.count; ++i) {
        if (hits.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID) {
            for (int k = 0; k < n_wavelengths; ++k) out[i][k] = dot(background_, basis[i][k]);
            continue;
        }
        const GeometryTable& table = table_of(hits.hit.geomID[i]);
        const unsigned prim = hits.hit.primID[i];
        const int material = table.material[prim];
        const Material& m = materials_[size_t(material)];
        if (m.kind == MaterialKind::Emissive) {
            // A monochromatic emitter is its line alone; any other, its colour's spectrum.
            const bool line = spectra.has_line(material);
            for (int k = 0; k < n_wavelengths; ++k)
                out[i][k] = line ? spectra.line_at(material, wavelengths_nm[i][k]) : dot(m.color, basis[i][k]);
            continue;
        }
        diffuse[i] = true;
        p[i] = rays.origin[i] + rays.direction[i] * hits.ray.tfar[i];
        n[i] = normalize(Vec3f{hits.hit.Ng_x[i], hits.hit.Ng_y[i], hits.hit.Ng_z[i]});
        if (dot(n[i], rays.direction[i]) > 0.0f) n[i] = -n[i];
        Vec3f p_texture = p[i];
        if (!table.velocity.empty())
            p_texture = p[i] - table.velocity[prim] * float(motion_.time_s(rays.time[i]));
        albedo[i] =
            (m.checker_size_m > 0.0f && checker_is_odd(p_texture, m.checker_size_m)) ? m.checker_color : m.color;
        for (int k = 0; k < n_wavelengths; ++k) out[i][k] = dot(m.emission, basis[i][k]);
    }

    // Shadow rays, one packet per light
    for (const PointLight& light : lights_) {
        alignas(kPacketAlignment) int shadow_valid[kPacketSize];
        alignas(kPacketAlignment) RTCRayPacket shadow;
        float cos_theta[kPacketSize] = {};
        float falloff[kPacketSize] = {};
        bool any = false;
        for (int i = 0; i < kPacketSize; ++i) {
            shadow_valid[i] = 0;
            // An idle lane holds a harmless ray (as scene.cpp: Embree's narrower kernels check every lane).
            shadow.org_x[i] = shadow.org_y[i] = shadow.org_z[i] = 0.0f;
            shadow.dir_x[i] = shadow.dir_y[i] = 0.0f, shadow.dir_z[i] = 1.0f;
            shadow.tnear[i] = shadow.tfar[i] = shadow.time[i] = 0.0f;
            if (i >= rays.count || !diffuse[i]) continue;
            Vec3f to_light = light.position_m - p[i];
            float to_light_m = length(to_light);
            cos_theta[i] = dot(n[i], to_light) / to_light_m;
            if (!(cos_theta[i] > 0.0f)) continue;
            falloff[i] = light.inverse_square ? 1.0f / std::max(to_light_m * to_light_m, kNearestFalloffM2) : 1.0f;
            Vec3f from = p[i] + n[i] * surface_offset(p[i]);
            Vec3f d = light.position_m - from;
            float dist = length(d);
            shadow.org_x[i] = from.x, shadow.org_y[i] = from.y, shadow.org_z[i] = from.z;
            shadow.dir_x[i] = d.x / dist, shadow.dir_y[i] = d.y / dist, shadow.dir_z[i] = d.z / dist;
            shadow.tnear[i] = 0.0f;
            shadow.tfar[i] = dist * (1.0f - 1e-5f);
            shadow.time[i] = rays.time[i];
            shadow.mask[i] = 0xFFFFFFFFu;
            shadow.id[i] = unsigned(i);
            shadow.flags[i] = 0;
            shadow_valid[i] = -1;
            any = true;
        }
        if (!any) continue;
        occluded_packet(shadow_valid, scene_, &context, &shadow);
        for (int i = 0; i < rays.count; ++i)
            if (shadow_valid[i] && shadow.tfar[i] != -kInf)
                // Reflectance spectrum times the light's spectrum, wavelength by wavelength.
                for (int k = 0; k < n_wavelengths; ++k)
                    out[i][k] += dot(albedo[i], basis[i][k]) * dot(light.intensity, basis[i][k]) *
                                 (cos_theta[i] * falloff[i]);
    }
}

}  // namespace lc
