// Scene::radiance for spectral renders: the same shading (emitters, Lambert
// diffuse lit by point lights with hard shadows, background for misses), each
// RGB colour of the file taken to a spectrum by the Mallett–Yuksel 2019 basis
// and evaluated at the ray's wavelengths (spectral.h). The tracing stages
// are the RGB path's (scene_trace.cpp); only the colours differ.
#include "scene.h"

namespace lc {
namespace {

constexpr int kW = kHeroWavelengths;

// The spectrum of colour c at one ray's four wavelengths: dot(c, basis) for
// each, 4 wide (the same operations in the same order as dot in vec.h).
inline void spectrum(const Vec3f& c, const float (&basis)[3][kW], float (&out)[kW]) {
    for (int m = 0; m < kW; ++m) out[m] = c.x * basis[0][m] + c.y * basis[1][m] + c.z * basis[2][m];
}

}  // namespace

void Scene::spectral_radiance(const RayBatch& rays, const float (*wavelengths_nm)[kW],
                              const float (*basis)[3][kW], float (*out)[kW]) const {
    const SpectralTables& spectra = *spectral_;
    CameraHits hits;
    trace_camera_rays(rays, hits);
    alignas(16) float reflectance[kPacketSize][kW];  // the diffuse hits' albedo spectra at the ray's wavelengths

    int material[kPacketSize];
    float unused_rgb[3][kPacketSize];
    gather_surfaces(rays, hits, material, unused_rgb);

    for (int i = 0; i < rays.count; ++i) {
        if (hits.missed(i)) {
            spectrum(background_, basis[i], out[i]);
            continue;
        }
        const Material& m = materials_[size_t(material[i])];
        if (m.kind == MaterialKind::Emissive) {
            // A monochromatic emitter is its line alone; any other, its colour's spectrum.
            if (spectra.has_line(material[i]))
                for (int k = 0; k < kW; ++k) out[i][k] = spectra.line_at(material[i], wavelengths_nm[i][k]);
            else
                spectrum(m.color, basis[i], out[i]);
            continue;
        }
        spectrum(m.emission, basis[i], out[i]);
    }
    surface_lanes(shading_kernel_, hits.packet, hits.surface);
    for (int i = 0; i < rays.count; ++i) {
        if (!hits.surface.diffuse[i]) continue;
        const Vec3f albedo{hits.surface.albedo[0][i], hits.surface.albedo[1][i], hits.surface.albedo[2][i]};
        spectrum(albedo, basis[i], reflectance[i]);
    }

    // Shadow rays, one packet per light
    for (const PointLight& light : lights_) {
        ShadowRays shadow;
        if (!trace_shadow_rays(light, hits, shadow)) continue;
        for (int i = 0; i < rays.count; ++i) {
            if (!shadow.lit(i)) continue;
            // Reflectance spectrum times the light's spectrum, wavelength by wavelength.
            float emitted[kW];
            spectrum(light.intensity, basis[i], emitted);
            const float geometry = shadow.lanes.cos_theta[i] * shadow.lanes.falloff[i];
            for (int k = 0; k < kW; ++k) out[i][k] += reflectance[i][k] * emitted[k] * geometry;
        }
    }
}

}  // namespace lc
