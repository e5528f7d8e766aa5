// Spectral renders: the tables lenscompare/spectral.py builds, and how a
// camera sample's wavelengths are drawn from them.
//
// Hero-wavelength sampling (Wilkie, Nawaz, Droske, Weidlich, Hanika, "Hero
// Wavelength Spectral Sampling", EGSR 2014): one sample dimension u gives the
// hero wavelength; the other three are u rotated by 1/4, 2/4, 3/4 through the
// same inverse CDF (for a uniform density: 100 nm apart, wrapping round
// 380-780 nm). Each wavelength is marginally distributed by the density, so
// the average of the four f(λ)/p(λ) is unbiased.
//
// Colours become spectra through the Mallett–Yuksel 2019 basis (a linear map,
// basis_at); the film's weight per wavelength is the CIE 1931 2° observer taken
// to linear sRGB (film_at). Both tables: every nm from 380 to 780.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "vec.h"

namespace lc {

constexpr int kHeroWavelengths = 4;

struct SpectralTables {
    static constexpr float kMinNm = 380.0f, kMaxNm = 780.0f;  // the tables step 1 nm between these
    std::vector<Vec3f> basis;  // Mallett–Yuksel basis spectra (r, g, b) per nm
    std::vector<Vec3f> film;   // linear-sRGB response per nm of radiance
    // Wavelength density, piecewise constant: segment i is [edges_nm[i],
    // edges_nm[i+1]) with probability cdf[i+1] - cdf[i].
    std::vector<float> edges_nm, cdf;
    // guide[j]: the segment holding u = j / kGuideCells, where the search for
    // u in [j, j + 1) / kGuideCells starts (a binary search's unpredictable
    // branches, four per sample, cost a fifth of a spectral render).
    static constexpr int kGuideCells = 2048;
    std::vector<uint32_t> guide;

    // Fills guide, density and inverse_density from edges_nm and cdf.
    void build_guide() {
        density.clear(), inverse_density.clear();
        for (size_t i = 0; i + 1 < cdf.size(); ++i) {
            const float p = cdf[i + 1] - cdf[i], width = edges_nm[i + 1] - edges_nm[i];
            density.push_back(p / width);
            inverse_density.push_back(p > 0.0f ? width / p : 0.0f);
        }
        guide.assign(kGuideCells, 0);
        size_t i = 0;
        for (int j = 0; j < kGuideCells; ++j) {
            const float u = float(j) / kGuideCells;
            while (i + 2 < cdf.size() && cdf[i + 1] <= u) ++i;
            guide[size_t(j)] = uint32_t(i);
        }
    }
    // Per material: its line (nm; 0: none) and the radiance per nm in the line's band.
    std::vector<float> line_nm, line_radiance;
    float line_half_width_nm = 0.5f;
    // A dispersive camera: true traces one ray per wavelength (4 per camera
    // sample), false traces the hero only and drops the secondaries (pbrt-v4's
    // TerminateSecondary).
    bool trace_secondaries = true;

    // Per segment, derived once (build_guide): density (1/nm) and its inverse,
    // which is also the nm per unit of u.
    std::vector<float> density, inverse_density;

    // The basis and the film's response over the density at nm (inverse_pdf: 1 / the density
    // there), by linear interpolation in the per-nm tables.
    void at(float nm, float inverse_pdf, Vec3f* basis_out, Vec3f* film_over_pdf_out) const {
        const float x = std::clamp(nm - kMinNm, 0.0f, kMaxNm - kMinNm);
        const int i = std::min(int(x), int(basis.size()) - 2);
        const float t = x - float(i);
        *basis_out = basis[size_t(i)] * (1.0f - t) + basis[size_t(i) + 1] * t;
        *film_over_pdf_out = (film[size_t(i)] * (1.0f - t) + film[size_t(i) + 1] * t) * inverse_pdf;
    }

    // Spectral radiance of a material's line at nm (0 outside its band, or with no line).
    float line_at(int material, float nm) const {
        const float line = line_nm[size_t(material)];
        return std::fabs(nm - line) <= line_half_width_nm ? line_radiance[size_t(material)] : 0.0f;
    }
    bool has_line(int material) const { return line_nm[size_t(material)] > 0.0f; }
};

// The four wavelengths of one camera sample, hero first, with what shading
// and the film need of each.
struct HeroWavelengths {
    float nm[kHeroWavelengths];
    Vec3f basis[kHeroWavelengths];          // the Mallett–Yuksel basis there
    Vec3f film_over_pdf[kHeroWavelengths];  // the film's response over the density there
};

// Fills *w in place (the caller's batch slot: no 112-byte copy per sample).
// Each wavelength by the inverse CDF: u in [0, 1) -> its segment, cdf[i] <=
// u < cdf[i+1] (the last one for u past every cdf), then nm and 1 / the
// density there. Stage by stage over the four wavelengths: each one's table
// lookups are a chain of dependent loads, and four chains side by side
// overlap (perf put this function at a tenth of a spectral thin-lens render).
inline void sample_hero_wavelengths(const SpectralTables& t, float u, HeroWavelengths* w) {
    float uk[kHeroWavelengths], inverse_pdf[kHeroWavelengths];
    size_t segment[kHeroWavelengths];
    for (int k = 0; k < kHeroWavelengths; ++k) {
        uk[k] = u + float(k) / kHeroWavelengths;
        if (uk[k] >= 1.0f) uk[k] -= 1.0f;
    }
    const float* cdf = t.cdf.data();
    const size_t n_cdf = t.cdf.size();
    constexpr int cells = SpectralTables::kGuideCells;
    for (int k = 0; k < kHeroWavelengths; ++k) segment[k] = t.guide[size_t(std::min(int(uk[k] * cells), cells - 1))];
    for (int k = 0; k < kHeroWavelengths; ++k)  // the one step a cell mostly needs, without a branch
        segment[k] += size_t((segment[k] + 2 < n_cdf) & (cdf[segment[k] + 1] <= uk[k]));
    for (int k = 0; k < kHeroWavelengths; ++k)
        while (segment[k] + 2 < n_cdf && cdf[segment[k] + 1] <= uk[k]) ++segment[k];
    const float *edges = t.edges_nm.data(), *inverse_density = t.inverse_density.data();
    for (int k = 0; k < kHeroWavelengths; ++k) {
        const size_t i = segment[k];
        w->nm[k] = std::clamp(edges[i] + (uk[k] - cdf[i]) * inverse_density[i], edges[i], edges[i + 1]);
        inverse_pdf[k] = inverse_density[i];
    }
    for (int k = 0; k < kHeroWavelengths; ++k) t.at(w->nm[k], inverse_pdf[k], &w->basis[k], &w->film_over_pdf[k]);
}

}  // namespace lc
