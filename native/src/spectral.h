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
    // away, with no search: nm = nm_at_u[j] + t * (nm_at_u[j + 1] - nm_at_u[j])
    // for u in cell j at fraction t, and its density 1 / ((nm_at_u[j + 1] -
    // nm_at_u[j]) * kInverseCells), exact for this piecewise-linear inverse CDF. The
    // density it samples differs from the one above only within cells that
    // hold a segment edge (a fraction of a nm of continuum per cell; a line's
    // 1 nm band spans hundreds): still every wavelength, each with its exact density,
    // so the estimate stays unbiased. (A search per wavelength, even guided,
    // was a fifth of a spectral thin-lens render: perf, session 7.)
    // 8192 cells: within a cell the density is flat while the film's
    // response is not, so wide cells add noise. Showcase's spectral thin lens
    // at 64 spp, relative RMSE over 4 seeds: 512 cells 0.0217, 2048 0.0178,
    // 8192 0.0169, 32768 0.0168; 8192 renders as fast as 2048, 32768 1-2 %
    // slower (session 8, with the tables of that session).
    static constexpr int kInverseCells = 8192;
    // A sample's four wavelengths fall in cells j, j + Q, j + 2Q, j + 3Q
    // (mod kInverseCells, Q = kInverseCells / 4) at the same fraction of
    // each. HeroQuad q holds cells q, q + Q, q + 2Q, q + 3Q as lanes 0-3, and
    // for each lane what a wavelength there needs, as its value at the
    // cell's start and its change across the cell: the nm, the basis and
    // the film's response over the density. One cell index then gives all
    // four wavelengths by one row (256 bytes; 512 KB in all) and a
    // multiply-add per value, 4 wide, where the per-nm tables took a
    // dependent chain per wavelength (cell, then nm, then the nm's row: over
    // 40 % of render_tile_spectral's samples on showcase's thin lens, perf, session 9). Across a cell the basis and film are taken linear,
    // the chord between the per-nm tables' values at its ends: exact for the
    // cells within one nm, and for the rest (a cell spans 0.05 nm on
    // average) off by a fraction of their kink. Not so for the wide cells
    // where the density is low (up to 55 nm at the ends of the range): the
    // chord there read red 0.055 % high in the mean (showcase, 1024 spp), so
    // a quad with a cell wider than kChordMaxNm reads the per-nm tables at
    // its wavelengths instead (about 90 of the 2048 quads; the chord's mean
    // film response then differs from the tables' by under 1e-6, numerically).
    static constexpr int kQuads = kInverseCells / 4;
    static constexpr float kChordMaxNm = 0.25f;
    struct alignas(64) HeroQuad {
        float nm[4], nm_step[4];
        float basis[3][4], basis_step[3][4];
        float film_over_pdf[3][4], film_over_pdf_step[3][4];
        bool exact;  // a cell wider than kChordMaxNm: read the per-nm tables
    };
    std::vector<HeroQuad> quads;

    // Fills quads from edges_nm and cdf, the basis and the film.
    void build_sampling_tables() {
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
        quads.assign(size_t(kQuads), HeroQuad{});
        for (int j = 0; j < kInverseCells; ++j) {
            HeroQuad& quad = quads[size_t(j % kQuads)];
            const int lane = j / kQuads;
            const float start_nm = nm_at_u[size_t(j)], end_nm = nm_at_u[size_t(j) + 1];
            const float width_nm = end_nm - start_nm;
            // The density in the cell is 1 / (width * cells): the film is divided by it.
            const float inverse_pdf = width_nm * float(kInverseCells);
            const Vec3f basis_start = basis_at(start_nm), basis_end = basis_at(end_nm);
            const Vec3f film_start = film_at(start_nm) * inverse_pdf, film_end = film_at(end_nm) * inverse_pdf;
            quad.nm[lane] = start_nm, quad.nm_step[lane] = width_nm;
            quad.exact = quad.exact || width_nm > kChordMaxNm;
            const float b0[3] = {basis_start.x, basis_start.y, basis_start.z};
            const float b1[3] = {basis_end.x, basis_end.y, basis_end.z};
            const float f0[3] = {film_start.x, film_start.y, film_start.z};
            const float f1[3] = {film_end.x, film_end.y, film_end.z};
            for (int c = 0; c < 3; ++c) {
                quad.basis[c][lane] = b0[c], quad.basis_step[c][lane] = b1[c] - b0[c];
                quad.film_over_pdf[c][lane] = f0[c], quad.film_over_pdf_step[c][lane] = f1[c] - f0[c];
            }
        }
    }

    // The basis and the film's response at nm, linear between the per-nm rows.
    Vec3f basis_at(float nm) const { return per_nm_at(basis, nm); }
    Vec3f film_at(float nm) const { return per_nm_at(film, nm); }
    static Vec3f per_nm_at(const std::vector<Vec3f>& table, float nm) {
        const float x = std::clamp(nm - kMinNm, 0.0f, kMaxNm - kMinNm);
        const int i = std::min(int(x), int(table.size()) - 2);
        const float t = x - float(i);
        return table[size_t(i)] + (table[size_t(i) + 1] - table[size_t(i)]) * t;
    }
    // Per material: its line (nm; 0: none) and the radiance per nm in the line's band.
    std::vector<float> line_nm, line_radiance;
    float line_half_width_nm = 0.5f;

    // A camera that does not disperse sends every wavelength along one ray,
    // so nothing on a path depends on the wavelength but the colours, and
    // with direct light only a path's spectrum is an emission E(λ) or a
    // reflectance times a light, R(λ) I(λ), each colour a sum over the basis.
    // The film's reading is then a fixed linear map of the RGB colours,
    //     ∫ film_k E = sum_c film_of_basis[k][c] e_c,
    //     ∫ film_k R I = sum_c sum_c' film_of_products[k][c][c'] r_c i_c',
    // taken here once, exactly for the per-nm tables (each integrand is a
    // cubic between rows: Simpson's rule per nm), so such a render draws no
    // wavelengths at all: no colour noise, one RGB-like sum per ray. It is
    // the sampled estimator's expectation (render_tile_spectral.h), which
    // integrate_still = false (render(sample_wavelengths=True)) renders instead.
    bool integrate_still = true;
    float film_of_basis[3][3] = {};
    float film_of_products[3][3][3] = {};
    std::vector<Vec3f> line_film;  // per material: the film's reading of its line (0: none)

    // Fills film_of_basis, film_of_products and line_film (after the lines are set).
    void build_wavelength_integrals() {
        double basis_sum[3][3] = {}, product_sum[3][3][3] = {};
        const double weight[3] = {1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0};  // Simpson's rule per nm: ends 1/6, middle 4/6
        for (size_t i = 0; i + 1 < basis.size(); ++i) {
            for (int q = 0; q < 3; ++q) {  // [i, i + 1] nm at its start, middle and end
                const double t = 0.5 * q;
                const Vec3f b = basis[i] + (basis[i + 1] - basis[i]) * float(t);
                const Vec3f f = film[i] + (film[i + 1] - film[i]) * float(t);
                const double bc[3] = {b.x, b.y, b.z}, fk[3] = {f.x, f.y, f.z};
                for (int k = 0; k < 3; ++k)
                    for (int c = 0; c < 3; ++c) {
                        basis_sum[k][c] += weight[q] * fk[k] * bc[c];
                        for (int d = 0; d < 3; ++d) product_sum[k][c][d] += weight[q] * fk[k] * bc[c] * bc[d];
                    }
            }
        }
        for (int k = 0; k < 3; ++k)
            for (int c = 0; c < 3; ++c) {
                film_of_basis[k][c] = float(basis_sum[k][c]);
                for (int d = 0; d < 3; ++d) film_of_products[k][c][d] = float(product_sum[k][c][d]);
            }
        line_film.assign(line_nm.size(), Vec3f{});
        for (size_t m = 0; m < line_nm.size(); ++m)
            if (line_nm[m] > 0.0f) line_film[m] = film_over_band(line_nm[m] - line_half_width_nm,
                                                                 line_nm[m] + line_half_width_nm) * line_radiance[m];
    }

    // ∫ film dλ over [from_nm, to_nm]: the trapezoid rule between the rows
    // and the band's ends, exact for the linear interpolation per_nm_at reads.
    Vec3f film_over_band(float from_nm, float to_nm) const {
        from_nm = std::clamp(from_nm, kMinNm, kMaxNm), to_nm = std::clamp(to_nm, kMinNm, kMaxNm);
        Vec3f sum{};
        for (float a = from_nm; a < to_nm;) {
            const float b = std::min(to_nm, std::floor(a) + 1.0f);
            sum += (film_at(a) + film_at(b)) * (0.5f * (b - a));
            a = b;
        }
        return sum;
    }

    // Film reading of a light of RGB intensity i off a reflectance of basis
    // colour r: sum_c film_of_light[k][c] r_c (film_of_products contracted with i).
    void film_of_light(const Vec3f& intensity, float (&out)[3][3]) const {
        for (int k = 0; k < 3; ++k)
            for (int c = 0; c < 3; ++c)
                out[k][c] = film_of_products[k][c][0] * intensity.x + film_of_products[k][c][1] * intensity.y +
                            film_of_products[k][c][2] * intensity.z;
    }

    // A dispersive camera traces this many of a sample's four wavelengths, a
    // ray each, evenly spaced through the rotation (1: the hero alone, as
    // pbrt-v4's TerminateSecondary; 2: the hero and the wavelength half the
    // distribution away; 4: all). Each traced one is still drawn from the
    // density, so any count is unbiased.
    int traced_wavelengths = kHeroWavelengths;

    // Spectral radiance of a material's line at nm (0 outside its band, or with no line).
    float line_at(int material, float nm) const {
        const float line = line_nm[size_t(material)];
        return std::fabs(nm - line) <= line_half_width_nm ? line_radiance[size_t(material)] : 0.0f;
    }
    bool has_line(int material) const { return line_nm[size_t(material)] > 0.0f; }
    bool any_line() const {
        return std::any_of(line_nm.begin(), line_nm.end(), [](float nm) { return nm > 0.0f; });
    }
};

// The four wavelengths of one camera sample, in the lanes of their HeroQuad
// (not hero first: the hero is lane hero_lane, wavelength k of the rotation
// lane (hero_lane + k) % 4), with what shading and the film need of each.
struct alignas(16) HeroWavelengths {
    float lane_nm[kHeroWavelengths];
    float basis[3][kHeroWavelengths];          // the Mallett–Yuksel basis there, channel by channel
    float film_over_pdf[3][kHeroWavelengths];  // the film's response over the density there
    float nm[kHeroWavelengths];                // hero first: lane_nm rotated, for the cameras
    int hero_lane;
    int lane(int k) const { return (hero_lane + k) & (kHeroWavelengths - 1); }
};

// The inverse-CDF cell u falls in.
inline int hero_cell(float u) {
    constexpr int cells = SpectralTables::kInverseCells;
    return std::min(int(u * float(cells)), cells - 1);
}

// The quad holding cell j's wavelengths (see SpectralTables::HeroQuad).
inline const SpectralTables::HeroQuad& hero_quad(const SpectralTables& t, int j) {
    return t.quads[size_t(j & (SpectralTables::kQuads - 1))];
}

// Starts loading the quad sample_hero_wavelengths(t, u) will read: the
// quads are 512 KB read at random, mostly from L2 and beyond.
inline void prefetch_hero_wavelengths(const SpectralTables& t, float u) {
    const char* q = reinterpret_cast<const char*>(&hero_quad(t, hero_cell(u)));
    for (size_t line = 0; line < sizeof(SpectralTables::HeroQuad); line += 64) __builtin_prefetch(q + line);
}

// Fills *w in place (the caller's batch slot): wavelength k from u + k / 4
// (mod 1) through the inverse CDF, i.e. one HeroQuad at one fraction.
inline void sample_hero_wavelengths(const SpectralTables& t, float u, HeroWavelengths* w) {
    constexpr int cells = SpectralTables::kInverseCells, quads = SpectralTables::kQuads;
    static_assert(quads * kHeroWavelengths == cells && (quads & (quads - 1)) == 0,
                  "u + k / 4 falls at the same place in its cell for every k");
    const int j = hero_cell(u);
    const float within = u * float(cells) - float(j);
    const SpectralTables::HeroQuad& q = hero_quad(t, j);
    for (int m = 0; m < kHeroWavelengths; ++m) w->lane_nm[m] = q.nm[m] + within * q.nm_step[m];
    for (int c = 0; c < 3; ++c)
        for (int m = 0; m < kHeroWavelengths; ++m) {
            w->basis[c][m] = q.basis[c][m] + within * q.basis_step[c][m];
            w->film_over_pdf[c][m] = q.film_over_pdf[c][m] + within * q.film_over_pdf_step[c][m];
        }
    if (__builtin_expect(q.exact, false))
        for (int m = 0; m < kHeroWavelengths; ++m) {
            const Vec3f basis = t.basis_at(w->lane_nm[m]);
            const Vec3f film = t.film_at(w->lane_nm[m]) * (q.nm_step[m] * float(cells));
            w->basis[0][m] = basis.x, w->basis[1][m] = basis.y, w->basis[2][m] = basis.z;
            w->film_over_pdf[0][m] = film.x, w->film_over_pdf[1][m] = film.y, w->film_over_pdf[2][m] = film.z;
        }
    w->hero_lane = j / quads;
    for (int k = 0; k < kHeroWavelengths; ++k) w->nm[k] = w->lane_nm[w->lane(k)];
}

}  // namespace lc
