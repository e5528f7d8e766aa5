// Scene::radiance for spectral renders: the same shading (emitters, Lambert
// diffuse lit by point lights with hard shadows, background for misses), each
// RGB colour of the file taken to a spectrum by the Mallett–Yuksel 2019 basis
// and evaluated at the ray's wavelengths (spectral.h). The tracing stages
// are the RGB path's (scene_trace.cpp); only the colours differ.
#include "scene.h"

namespace lc {

void Scene::spectral_radiance(const RayBatch& rays, const float (*wavelengths_nm)[kHeroWavelengths],
                              const Vec3f (*basis)[kHeroWavelengths], int n_wavelengths,
                              float (*out)[kHeroWavelengths]) const {
    const SpectralTables& spectra = *spectral_;
    CameraHits hits;
    trace_camera_rays(rays, hits);
    float reflectance[kPacketSize][kHeroWavelengths];  // the diffuse hits' albedo spectra at the ray's wavelengths

    int material[kPacketSize];
    float unused_rgb[3][kPacketSize];
    gather_surfaces(rays, hits, material, unused_rgb);

    // A colour c is dot(c, basis) at each ray's wavelengths.
    for (int i = 0; i < rays.count; ++i) {
        if (hits.missed(i)) {
            for (int k = 0; k < n_wavelengths; ++k) out[i][k] = dot(background_, basis[i][k]);
            continue;
        }
        const Material& m = materials_[size_t(material[i])];
        if (m.kind == MaterialKind::Emissive) {
            // A monochromatic emitter is its line alone; any other, its colour's spectrum.
            const bool line = spectra.has_line(material[i]);
            for (int k = 0; k < n_wavelengths; ++k)
                out[i][k] = line ? spectra.line_at(material[i], wavelengths_nm[i][k]) : dot(m.color, basis[i][k]);
            continue;
        }
        for (int k = 0; k < n_wavelengths; ++k) out[i][k] = dot(m.emission, basis[i][k]);
    }
    surface_lanes(shading_kernel_, hits.packet, hits.surface);
    for (int i = 0; i < rays.count; ++i) {
        if (!hits.surface.diffuse[i]) continue;
        const Vec3f albedo{hits.surface.albedo[0][i], hits.surface.albedo[1][i], hits.surface.albedo[2][i]};
        for (int k = 0; k < n_wavelengths; ++k) reflectance[i][k] = dot(albedo, basis[i][k]);
    }

    // Shadow rays, one packet per light
    for (const PointLight& light : lights_) {
        ShadowRays shadow;
        if (!trace_shadow_rays(light, hits, shadow)) continue;
        for (int i = 0; i < rays.count; ++i)
            if (shadow.lit(i))
                // Reflectance spectrum times the light's spectrum, wavelength by wavelength.
                for (int k = 0; k < n_wavelengths; ++k)
                    out[i][k] += reflectance[i][k] * dot(light.intensity, basis[i][k]) *
                                 (shadow.lanes.cos_theta[i] * shadow.lanes.falloff[i]);
    }
}

}  // namespace lc
