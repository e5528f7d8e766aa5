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
    // edges_nm[i+1]) with probability cdf[i+1] - cdf[i] (lenscompare/spectral.py).
    std::vector<float> edges_nm, cdf;
    // What a sample draws from: that density's inverse CDF at kInverseCells + 1
    // evenly spaced u, linear between. A wavelength is then one table row
    // away, with no search: nm = nm_at_u[j] + t * nm_per_cell[j] for u in
    // cell j at fraction t, and its density 1 / (nm_per_cell[j] *
    // kInverseCells), exact for this piecewise-linear inverse CDF. The
    // density it samples differs from the one above only within cells that
    // hold a segment edge (a fraction of a nm of continuum per cell; a line's
    // 1 nm band spans hundreds): still every wavelength, each with its exact density,
    // so the estimate stays unbiased. (A search per wavelength, even guided,
    // was a fifth of a spectral thin-lens render: perf, session 7.)
    // 8192 cells (64 KB): within a cell the density is flat while the film's
    // response is not, so wide cells add noise. Showcase's spectral thin lens
    // at 64 spp, relative RMSE over 4 seeds: 512 cells 0.0217, 2048 0.0178,
    // 8192 0.0169, 32768 0.0168; 8192 renders as fast as 2048, 32768 1-2 %
    // slower (session 8).
    static constexpr int kInverseCells = 8192;
    struct InverseCell {
        float nm, nm_per_cell;
    };
    std::vector<InverseCell> inverse_cdf;  // kInverseCells + 1 rows, the last a sentinel

    // Fills inverse_cdf from edges_nm and cdf, and per_nm from basis and film.
    void build_sampling_tables() {
        per_nm.clear();
        for (size_t i = 0; i < basis.size(); ++i) {
            const size_t next = std::min(i + 1, basis.size() - 1);
            per_nm.push_back({basis[i], basis[next] - basis[i], film[i], film[next] - film[i]});
        }
        std::vector<float> nm_at_u(size_t(kInverseCells) + 1);
        size_t i = 0;
        for (int j = 0; j <= kInverseCells; ++j) {
            const double u = double(j) / kInverseCells;
            while (i + 2 < cdf.size() && double(cdf[i + 1]) <= u) ++i;
            const double p = double(cdf[i + 1]) - double(cdf[i]);
            const double t = p > 0.0 ? std::clamp((u - double(cdf[i])) / p, 0.0, 1.0) : 0.0;
            nm_at_u[size_t(j)] = float(double(edges_nm[i]) + t * (double(edges_nm[i + 1]) - double(edges_nm[i])));
        }
        nm_at_u.front() = edges_nm.front(), nm_at_u.back() = edges_nm.back();
        inverse_cdf.assign(size_t(kInverseCells) + 1, InverseCell{edges_nm.back(), 0.0f});
        for (int j = 0; j < kInverseCells; ++j)
            inverse_cdf[size_t(j)] = {nm_at_u[size_t(j)], nm_at_u[size_t(j) + 1] - nm_at_u[size_t(j)]};
    }
    // Per material: its line (nm; 0: none) and the radiance per nm in the line's band.
    std::vector<float> line_nm, line_radiance;
    float line_half_width_nm = 0.5f;
    // A dispersive camera traces this many of a sample's four wavelengths, a
    // ray each, evenly spaced through the rotation (1: the hero alone, as
    // pbrt-v4's TerminateSecondary; 2: the hero and the wavelength half the
    // distribution away; 4: all). Each traced one is still drawn from the
    // density, so any count is unbiased.
    int traced_wavelengths = kHeroWavelengths;

    // The basis and the film's response over the density at nm (inverse_pdf: 1 / the density
    // there), by linear interpolation in the per-nm tables.
    void at(float nm, float inverse_pdf, Vec3f* basis_out, Vec3f* film_over_pdf_out) const {
        const float x = std::clamp(nm - kMinNm, 0.0f, kMaxNm - kMinNm);
        const int i = std::min(int(x), int(per_nm.size()) - 2);
        const float t = x - float(i);
        const NmRow& row = per_nm[size_t(i)];
        *basis_out = row.basis + row.basis_step * t;
        *film_over_pdf_out = (row.film + row.film_step * t) * inverse_pdf;
    }

    // basis and film, with each row's step to the next: one row per look-up
    // and a multiply-add per interpolation (built by build_sampling_tables).
    struct NmRow {
        Vec3f basis, basis_step, film, film_step;
    };
    std::vector<NmRow> per_nm;

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

// Fills *w in place (the caller's batch slot: no 112-byte copy per sample):
// wavelength k from u + k / 4 (mod 1) through the inverse-CDF table, then the
// basis and film response there.
inline void sample_hero_wavelengths(const SpectralTables& t, float u, HeroWavelengths* w) {
    constexpr int cells = SpectralTables::kInverseCells;
    static_assert(cells % kHeroWavelengths == 0, "u + k / 4 falls at the same place in its cell for every k");
    const SpectralTables::InverseCell* table = t.inverse_cdf.data();
    const float x = u * float(cells);
    const int j = std::min(int(x), cells - 1);
    const float within = x - float(j);
    float inverse_pdf[kHeroWavelengths];
    for (int k = 0; k < kHeroWavelengths; ++k) {
        const SpectralTables::InverseCell cell = table[(j + k * (cells / kHeroWavelengths)) % cells];
        w->nm[k] = cell.nm + within * cell.nm_per_cell;
        inverse_pdf[k] = cell.nm_per_cell * float(cells);
    }
    for (int k = 0; k < kHeroWavelengths; ++k) t.at(w->nm[k], inverse_pdf[k], &w->basis[k], &w->film_over_pdf[k]);
}

}  // namespace lc
