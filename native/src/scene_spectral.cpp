// Scene::radiance for spectral renders: the same shading (emitters, Lambert
// diffuse lit by point lights with hard shadows, background for misses), each
// RGB colour of the file taken to a spectrum by the Mallett–Yuksel 2019 basis
// and evaluated at the ray's wavelengths (spectral.h). The tracing stages
// are the RGB path's (scene_trace.cpp); only the colours differ.
#include "scene.h"

#include <algorithm>
#include <cstring>

#include "cpu_kernels.h"

namespace lc {
namespace {

constexpr int kW = kHeroWavelengths;

// The spectrum of colour (r, g, b) at one ray's four wavelengths: dot(c,
// basis) for each, 4 wide (the operations of dot in vec.h, in its order).
inline void spectrum(float r, float g, float b, const float (&basis)[3][kW], float (&out)[kW]) {
    float s[kW];
    for (int m = 0; m < kW; ++m) s[m] = r * basis[0][m] + g * basis[1][m] + b * basis[2][m];
    for (int m = 0; m < kW; ++m) out[m] = s[m];
}

}  // namespace

// Lane by lane without branches where it can (as shading_lanes.cpp): every
// ray's four wavelengths are one 4-wide step, and a lane a light does not
// reach adds that light times 0.
LC_BUILT_PER_ISA void Scene::spectral_radiance(const RayBatch& rays, const HeroWavelengths* const* wavelengths,
                                               float (*out)[kW]) const {
    const SpectralTables& spectra = *spectral_;
    CameraHits hits;
    trace_camera_rays(rays, hits);

    // Each lane's radiance before any light (an emitter's colour, a diffuse
    // emission, the background) as gather_lanes puts it in start.
    int material[kPacketSize];
    float start[3][kPacketSize];
    gather_surfaces(rays, hits, material, start);
    for (int i = 0; i < rays.count; ++i)
        spectrum(start[0][i], start[1][i], start[2][i], wavelengths[i]->basis, out[i]);
    // A monochromatic emitter is its line alone.
    if (spectra.any_line())
        for (int i = 0; i < rays.count; ++i)
            if (shows_line(hits, material, i))
                for (int k = 0; k < kW; ++k) out[i][k] = spectra.line_at(material[i], wavelengths[i]->lane_nm[k]);
    if (lights_.empty() || !any_diffuse(hits.surface)) return;

    surface_lanes(shading_kernel_, hits.packet, hits.surface);
    alignas(16) float reflectance[kPacketSize][kW];  // the diffuse hits' albedo spectra (0 elsewhere)
    for (int i = 0; i < rays.count; ++i) {
        const SurfaceLanes& s = hits.surface;
        float r[kW];
        spectrum(s.albedo[0][i], s.albedo[1][i], s.albedo[2][i], wavelengths[i]->basis, r);
        for (int k = 0; k < kW; ++k) reflectance[i][k] = s.diffuse[i] ? r[k] : 0.0f;
    }

    // Shadow rays, one packet per light
    for (size_t l = 0; l < lights_.size(); ++l) {
        const PointLight& light = lights_[l];
        ShadowRays shadow;
        if (!trace_shadow_rays(l, hits, shadow)) continue;
        for (int i = 0; i < rays.count; ++i) {
            // Reflectance spectrum times the light's spectrum, wavelength by wavelength.
            float emitted[kW];
            spectrum(light.intensity.x, light.intensity.y, light.intensity.z, wavelengths[i]->basis, emitted);
            const float geometry = shadow.lit(i) ? shadow.lanes.cos_theta[i] * shadow.lanes.falloff[i] : 0.0f;
            for (int k = 0; k < kW; ++k) out[i][k] += reflectance[i][k] * emitted[k] * geometry;
        }
    }
}

// Through a camera that does not disperse: the wavelengths' integral,
// exact (spectral.h, integrate_still), as RGB-like sums. Each colour of the
// file reaches the film through film_of_basis, a lit reflectance through
// its light's film_of_light: the RGB path's stages with those maps between
// (spectral_band_radiance's with every ray carrying the whole spectrum).
void Scene::spectral_integrated_radiance(const RayBatch& rays, Vec3f* out) const {
    spectral_band_radiance(rays, nullptr, out);
}

// Through a dispersive thin or thick lens (render_tile_bands.h): each ray's
// integral taken over its own band of planes of focus (bands null: every
// ray the whole spectrum, spectral_integrated_radiance). Each ray is shaded
// through the whole spectrum's maps, and one carrying a band gets its own
// maps in their place before each is applied.
LC_BUILT_PER_ISA void Scene::spectral_band_radiance(const RayBatch& rays, const RayFocusBands* bands,
                                                    Vec3f* out) const {
    const SpectralTables& spectra = *spectral_;
    CameraHits hits;
    trace_camera_rays(rays, hits);

    float start[3][kPacketSize], rgb[3][kPacketSize];
    int material[kPacketSize];
    gather_surfaces(rays, hits, material, start);
    map_colour_lanes(shading_kernel_, spectra.film_of_basis, start, rgb);
    // Where each ray's band begins and ends in the integrals' tables, shared by the basis and the lights.
    FocusBandIntegrals::End lo[kPacketSize], hi[kPacketSize];
    FocusBandIntegrals::LastRead last_read;  // per table, over the packet's rays in order
    if (bands)
        for (int i = 0; i < rays.count; ++i) {
            lo[i] = bands->integrals->end_at(bands->k_lo[i]), hi[i] = bands->integrals->end_at(bands->k_hi[i]);
            if (start[0][i] == 0.0f && start[1][i] == 0.0f && start[2][i] == 0.0f) continue;  // no light of its own
            float mapped[3];
            bands->integrals->apply(0, lo[i], hi[i], start[0][i], start[1][i], start[2][i], mapped, &last_read);
            const float t = bands->whole_part[i];
            rgb[0][i] = mapped[0] + t * rgb[0][i], rgb[1][i] = mapped[1] + t * rgb[1][i];
            rgb[2][i] = mapped[2] + t * rgb[2][i];
        }
    // A monochromatic emitter is its line alone: the part of its band the ray carries.
    if (spectra.any_line())
        for (int i = 0; i < rays.count; ++i)
            if (shows_line(hits, material, i)) {
                const size_t m = size_t(material[i]);
                Vec3f line = spectra.line_film[m];
                if (bands) {
                    WavelengthBand band;
                    bands->runs->band_of(bands->k_lo[i], bands->k_hi[i], &band);
                    line = line * bands->whole_part[i];
                    const float from = spectra.line_nm[m] - spectra.line_half_width_nm;
                    const float to = spectra.line_nm[m] + spectra.line_half_width_nm;
                    for (int r = 0; r < band.count; ++r)
                        line += spectra.film_over_band(std::max(from, band.from_nm[r]), std::min(to, band.to_nm[r])) *
                                spectra.line_radiance[m];
                }
                rgb[0][i] = line.x, rgb[1][i] = line.y, rgb[2][i] = line.z;
            }
    if (!lights_.empty() && any_diffuse(hits.surface)) {
        surface_lanes(shading_kernel_, hits.packet, hits.surface);
        SurfaceLanes& surface = hits.surface;
        float albedo[3][kPacketSize];  // the albedo as a basis colour; surface.albedo gets each light's map of it
        std::memcpy(albedo, surface.albedo, sizeof albedo);
        const float white[3] = {1.0f, 1.0f, 1.0f};
        for (size_t l = 0; l < lights_.size(); ++l) {
            ShadowRays shadow;
            if (!trace_shadow_rays(l, hits, shadow)) continue;
            map_colour_lanes(shading_kernel_, film_of_lights_[l].of_basis, albedo, surface.albedo);
            if (!bands) {
                add_light_lanes(shading_kernel_, white, surface, shadow.lanes, shadow.packet.tfar, rgb);
                continue;
            }
            // Each lit ray's band map of its albedo, and add_light_lanes' sum
            // for it here, lane by lane: that function's whole-row loads of
            // rows just written a lane at a time here waited for those stores
            // to reach the cache (a load spanning several stores is not
            // forwarded from them). The same operations in the same order.
            last_read = {};
            for (int i = 0; i < rays.count; ++i) {
                if (!surface.diffuse[i] || !shadow.lit(i)) continue;  // this light adds nothing there
                float mapped[3];
                bands->integrals->apply(1 + int(l), lo[i], hi[i], albedo[0][i], albedo[1][i], albedo[2][i], mapped,
                                        &last_read);
                const float t = bands->whole_part[i];
                const float scale = shadow.lanes.cos_theta[i] * shadow.lanes.falloff[i];
                for (int k = 0; k < 3; ++k) {
                    const float lit_albedo = mapped[k] + t * surface.albedo[k][i];
                    rgb[k][i] = rgb[k][i] + lit_albedo * white[k] * scale;
                }
            }
        }
    }
    write_radiance(rays.count, rgb, out);
}

void Scene::set_spectral(std::shared_ptr<const SpectralTables> tables) {
    spectral_ = std::move(tables);
    film_of_lights_.assign(lights_.size(), FilmMap{});
    for (size_t l = 0; l < lights_.size(); ++l) spectral_->film_of_light(lights_[l].intensity, film_of_lights_[l].of_basis);
}

FocusBandIntegrals Scene::focus_band_integrals(const std::vector<double>& inverse_focus_per_m_by_nm) const {
    std::vector<Vec3f> intensities;
    for (const PointLight& light : lights_) intensities.push_back(light.intensity);
    return FocusBandIntegrals(*spectral_, intensities, inverse_focus_per_m_by_nm);
}

}  // namespace lc
