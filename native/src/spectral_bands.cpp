#include "spectral_bands.h"

#include <cmath>
#include <stdexcept>

namespace lc {
namespace {

// The integrand in nm cell j ([380 + j, 381 + j], t in [0, 1]) for each of
// the nine entries (k * 3 + c): film_k times basis B_c times the light's
// spectrum (1 without a light), a cubic in t, coefficients of t^0 .. t^3.
// Each factor is linear within the nm, as the per-nm tables are read.
void cell_integrand(const SpectralTables& t, size_t j, const Vec3f* intensity, double out[9][4]) {
    const Vec3f f0 = t.film[j], f1 = t.film[j + 1], b0 = t.basis[j], b1 = t.basis[j + 1];
    const double film[3][2] = {{f0.x, f1.x - f0.x}, {f0.y, f1.y - f0.y}, {f0.z, f1.z - f0.z}};
    const double basis[3][2] = {{b0.x, b1.x - b0.x}, {b0.y, b1.y - b0.y}, {b0.z, b1.z - b0.z}};
    double light[2] = {1.0, 0.0};  // a + b t
    if (intensity) {
        const double i[3] = {intensity->x, intensity->y, intensity->z};
        light[0] = i[0] * basis[0][0] + i[1] * basis[1][0] + i[2] * basis[2][0];
        light[1] = i[0] * basis[0][1] + i[1] * basis[1][1] + i[2] * basis[2][1];
    }
    for (int k = 0; k < 3; ++k)
        for (int c = 0; c < 3; ++c) {
            // (f + f' t)(b + b' t)(l + l' t)
            const double p0 = film[k][0] * basis[c][0];
            const double p1 = film[k][0] * basis[c][1] + film[k][1] * basis[c][0];
            const double p2 = film[k][1] * basis[c][1];
            double* a = out[3 * k + c];
            a[0] = p0 * light[0], a[1] = p0 * light[1] + p1 * light[0];
            a[2] = p1 * light[1] + p2 * light[0], a[3] = p2 * light[1];
        }
}

}  // namespace

FocusBandIntegrals::FocusBandIntegrals(const SpectralTables& t, const std::vector<Vec3f>& light_intensities,
                                       const std::vector<double>& inverse_focus_per_m_by_nm) {
    const std::vector<double>& k = inverse_focus_per_m_by_nm;
    if (k.size() < 2 || t.basis.size() < 2) throw std::invalid_argument("a band needs two planes of focus");
    const size_t cells = std::min(t.basis.size(), k.size()) - 1;
    tables_ = 1 + int(light_intensities.size());

    breaks_.assign(k.begin(), k.begin() + std::ptrdiff_t(cells + 1));
    std::sort(breaks_.begin(), breaks_.end());
    breaks_.erase(std::unique(breaks_.begin(), breaks_.end()), breaks_.end());
    if (breaks_.size() < 2) throw std::invalid_argument("a lens whose focus does not move carries no bands");
    const size_t intervals = breaks_.size() - 1;
    inverse_width_.resize(intervals);
    for (size_t i = 0; i < intervals; ++i) inverse_width_[i] = 1.0 / (breaks_[i + 1] - breaks_[i]);
    guide_.resize(4 * breaks_.size());
    guide_scale_ = double(guide_.size()) / (breaks_.back() - breaks_.front());
    for (size_t g = 0; g < guide_.size(); ++g) {
        const double at = breaks_.front() + double(g) / guide_scale_;
        const size_t above = size_t(std::upper_bound(breaks_.begin(), breaks_.end(), at) - breaks_.begin());
        guide_[g] = int(std::clamp<size_t>(above, 1, intervals) - 1);
    }

    // F's quartic per interval, in double: each cell adds its whole
    // integral to the intervals above its planes, and over the intervals its
    // planes span the part of it on the near side of k (rising: t below
    // k's, falling: above).
    std::vector<double> poly(intervals * size_t(tables_) * 9 * 5, 0.0);
    std::vector<double> below(breaks_.size() * size_t(tables_) * 9, 0.0);  // added from interval i on
    whole_.assign(size_t(tables_), Sum{});
    std::vector<double> whole(size_t(tables_) * 9, 0.0);
    for (int table = 0; table < tables_; ++table) {
        const Vec3f* intensity = table == 0 ? nullptr : &light_intensities[size_t(table - 1)];
        for (size_t j = 0; j < cells; ++j) {
            double a[9][4];
            cell_integrand(t, j, intensity, a);
            double b[9][4], full[9];  // G(τ) = sum_m b_m τ^(m + 1), full = G(1)
            for (int e = 0; e < 9; ++e) {
                full[e] = 0.0;
                for (int m = 0; m < 4; ++m) b[e][m] = a[e][m] / double(m + 1), full[e] += b[e][m];
                whole[size_t(table) * 9 + size_t(e)] += full[e];
            }
            const double k0 = k[j], k1 = k[j + 1], lo = std::min(k0, k1), hi = std::max(k0, k1);
            // Intervals [first, last) lie within [lo, hi]; from interval last on the cell is whole.
            const size_t first = size_t(std::lower_bound(breaks_.begin(), breaks_.end(), lo) - breaks_.begin());
            const size_t last = size_t(std::lower_bound(breaks_.begin(), breaks_.end(), hi) - breaks_.begin());
            for (int e = 0; e < 9; ++e) below[(last * size_t(tables_) + size_t(table)) * 9 + size_t(e)] += full[e];
            for (size_t i = first; i < last; ++i) {
                // τ = (K - k0) / (k1 - k0) with K = breaks_[i] + s w: α + β s.
                const double alpha = (breaks_[i] - k0) / (k1 - k0);
                const double beta = (breaks_[i + 1] - breaks_[i]) / (k1 - k0);
                // (α + β s)^p's coefficients of s^q, p = 1 .. 4
                double power[5][5] = {{1.0}};
                for (int p = 1; p <= 4; ++p)
                    for (int q = 0; q <= p; ++q)
                        power[p][q] = (q < p ? power[p - 1][q] * alpha : 0.0) + (q > 0 ? power[p - 1][q - 1] * beta : 0.0);
                const bool rising = k1 > k0;
                double* out = &poly[(i * size_t(tables_) + size_t(table)) * 45];
                for (int e = 0; e < 9; ++e) {
                    double g[5] = {};
                    for (int m = 0; m < 4; ++m)
                        for (int q = 0; q <= m + 1; ++q) g[q] += b[e][m] * power[m + 1][q];
                    if (!rising) {  // the part above τ: full - G
                        for (double& v : g) v = -v;
                        g[0] += full[e];
                    }
                    for (int q = 0; q < 5; ++q) out[e * 5 + q] += g[q];
                }
            }
        }
    }
    cells_.assign(intervals * size_t(tables_), Cell{});
    for (int table = 0; table < tables_; ++table) {
        double sum_below[9] = {};
        for (size_t i = 0; i < intervals; ++i) {
            const size_t at = i * size_t(tables_) + size_t(table);
            for (int e = 0; e < 9; ++e) sum_below[e] += below[at * 9 + size_t(e)];
            Cell& cell = cells_[at];
            for (int e = 0; e < 9; ++e)
                for (int q = 0; q < 5; ++q)
                    cell.c[q][e % 3][e / 3] = float((q == 0 ? sum_below[e] : 0.0) + poly[at * 45 + size_t(e) * 5 + size_t(q)]);
        }
        for (int e = 0; e < 9; ++e) whole_[size_t(table)].e[e % 3][e / 3] = float(whole[size_t(table) * 9 + size_t(e)]);
    }
    build_white_shares();
}

void FocusBandIntegrals::build_white_shares() {
    const double lowest = breaks_.front(), highest = breaks_.back();
    share_steps_per_k_ = double(kShareSteps) / (highest - lowest);
    float whole[3];
    apply(0, end_at(lowest), end_at(highest), 1.0f, 1.0f, 1.0f, whole);
    share_below_.resize(size_t(kShareSteps) + 1), share_above_.resize(size_t(kShareSteps) + 1);
    for (int step = 0; step <= kShareSteps; ++step) {
        const End at = end_at(lowest + double(step) / share_steps_per_k_);
        float below[3], above[3];
        apply(0, end_at(lowest), at, 1.0f, 1.0f, 1.0f, below);
        apply(0, at, end_at(highest), 1.0f, 1.0f, 1.0f, above);
        float most_below = 0.0f, most_above = 0.0f;
        for (int c = 0; c < 3; ++c) {
            if (!(whole[c] > 0.0f)) continue;
            most_below = std::max(most_below, below[c] / whole[c]);
            most_above = std::max(most_above, above[c] / whole[c]);
        }
        share_below_[size_t(step)] = most_below, share_above_[size_t(step)] = most_above;
    }
}

}  // namespace lc
