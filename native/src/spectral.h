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
    // Per material: its line (nm; 0: none) and the radiance per nm in the line's band.
    std::vector<float> line_nm, line_radiance;
    float line_half_width_nm = 0.5f;
    // A dispersive camera: true traces one ray per wavelength (4 per camera
    // sample), false traces the hero only and drops the secondaries (pbrt-v4's
    // TerminateSecondary).
    bool trace_secondaries = true;

    // Linear interpolation in a per-nm table.
    Vec3f at(const std::vector<Vec3f>& table, float nm) const {
        const float x = std::clamp(nm - kMinNm, 0.0f, kMaxNm - kMinNm);
        const size_t i = std::min(size_t(x), table.size() - 2);
        const float t = x - float(i);
        return table[i] * (1.0f - t) + table[i + 1] * t;
    }
    Vec3f basis_at(float nm) const { return at(basis, nm); }
    Vec3f film_at(float nm) const { return at(film, nm); }

    // u in [0, 1) -> wavelength (nm) and its density (1/nm), by the inverse CDF.
    void sample(float u, float* nm, float* pdf) const {
        // The segment holding u: cdf[i] <= u < cdf[i+1]
        size_t i = size_t(std::upper_bound(cdf.begin() + 1, cdf.end() - 1, u) - cdf.begin()) - 1;
        const float p = cdf[i + 1] - cdf[i], width = edges_nm[i + 1] - edges_nm[i];
        const float t = p > 0.0f ? (u - cdf[i]) / p : 0.5f;
        *nm = std::min(edges_nm[i] + std::clamp(t, 0.0f, 1.0f) * width, kMaxNm);
        *pdf = p / width;
    }

    // Spectral radiance of a material's line at nm (0 outside its band, or with no line).
    float line_at(int material, float nm) const {
        const float line = line_nm[size_t(material)];
        return std::fabs(nm - line) <= line_half_width_nm ? line_radiance[size_t(material)] : 0.0f;
    }
    bool has_line(int material) const { return line_nm[size_t(material)] > 0.0f; }
};

// The four wavelengths of one camera sample, hero first.
struct HeroWavelengths {
    float nm[kHeroWavelengths];
    float pdf[kHeroWavelengths];  // density, 1/nm
};

inline HeroWavelengths sample_hero_wavelengths(const SpectralTables& t, float u) {
    HeroWavelengths w;
    for (int k = 0; k < kHeroWavelengths; ++k) {
        float uk = u + float(k) / kHeroWavelengths;
        if (uk >= 1.0f) uk -= 1.0f;
        t.sample(uk, &w.nm[k], &w.pdf[k]);
    }
    return w;
}

}  // namespace lc
