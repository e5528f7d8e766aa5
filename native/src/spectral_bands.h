// The film's reading of a spectrum over a band of wavelengths, exactly: what
// a spectral render needs when each ray of a dispersive thin or thick lens
// carries a band of the spectrum rather than a few drawn wavelengths
// (render_tile_bands.h).
//
// Along one ray, with the contract's direct light, a path's spectrum is an
// emission E(λ) = sum_c e_c B_c(λ) or a reflectance times a light,
// R(λ) I(λ) (spectral.h). The film's reading of it over a set S of
// wavelengths is then a 3 x 3 map of the file's colours, as for the whole
// range (SpectralTables::film_of_basis), only integrated over S:
//     ∫_S film_k E = sum_c [∫_S film_k B_c] e_c,
//     ∫_S film_k R I = sum_c [∫_S film_k B_c I] r_c.
// BandIntegral holds such a map's integral from 380 nm to any wavelength,
// exact for the per-nm tables read linearly (the integrand is a product of
// two or three linear functions within a nm: a polynomial, integrated per
// nm in closed form); a band's map is the difference at its ends.
//
// DispersionRuns turns a band of planes of focus (1 / focus, 1/m, the
// thin lens's table, linear between whole nm) into the wavelengths whose
// plane of focus lies in it: one interval per stretch of the table that
// rises or falls (a singlet's has one; an achromat's, whose focus turns
// back, two).
#pragma once

#include <algorithm>
#include <array>
#include <vector>

#include "spectral.h"
#include "vec.h"

namespace lc {

// At most this many monotone stretches of a lens's plane of focus over
// 380-780 nm for its rays to carry bands; past it (an apochromat turns
// twice, so has three) the render draws wavelengths instead.
constexpr int kMaxBandRuns = 4;

// A set of wavelengths a ray carries: count intervals [from_nm, to_nm], or
// all of 380-780 nm when count < 0.
struct WavelengthBand {
    int count = -1;
    float from_nm[kMaxBandRuns], to_nm[kMaxBandRuns];
    bool whole() const { return count < 0; }
};

class BandIntegral {
  public:
    using Map = float[3][3];

    // ∫ film_k B_c dλ: the emission map, film_of_basis over a band.
    static BandIntegral of_basis(const SpectralTables& t) { return BandIntegral(t, nullptr); }
    // ∫ film_k B_c I dλ for a light of RGB intensity i (I = sum_d i_d B_d):
    // its reflectance map, SpectralTables::film_of_light over a band.
    static BandIntegral of_light(const SpectralTables& t, const Vec3f& intensity) {
        return BandIntegral(t, &intensity);
    }

    // The map over band into out.
    void over(const WavelengthBand& band, Map& out) const {
        Entries sum = {};
        if (band.whole())
            for (int v = 0; v < kVectors; ++v) sum[v] = whole_[v];
        for (int r = 0; r < band.count; ++r) {
            Entries from, to;
            up_to(band.from_nm[r], from);
            up_to(band.to_nm[r], to);
            for (int v = 0; v < kVectors; ++v) sum[v] += to[v] - from[v];
        }
        for (int e = 0; e < 9; ++e) out[e / 3][e % 3] = sum[e / 4][e % 4];
    }

  private:
    // Per nm cell j ([380 + j, 381 + j]): the integral from 380 nm to its
    // start, and the in-cell integral's coefficients, ∫_0^t f = t (b0 + t (b1
    // + t (b2 + t b3))), for each of the nine entries (k * 3 + c), padded
    // with zeros to three 4-wide vectors (GCC's vector extension: written
    // as floats, the entries' loop stayed scalar, a fifth of a render, perf).
    typedef float Lanes __attribute__((vector_size(16)));
    static constexpr int kVectors = 3;
    using Entries = Lanes[kVectors];
    struct Cell {
        Entries start;
        Entries b[4];
    };

    BandIntegral(const SpectralTables& t, const Vec3f* intensity) {
        const size_t cells = t.basis.size() - 1;
        cells_.assign(cells, Cell{});
        double start[9] = {};
        for (size_t j = 0; j < cells; ++j) {
            const Vec3f f0 = t.film[j], f1 = t.film[j + 1], b0 = t.basis[j], b1 = t.basis[j + 1];
            const double film[3][2] = {{f0.x, f1.x - f0.x}, {f0.y, f1.y - f0.y}, {f0.z, f1.z - f0.z}};
            const double basis[3][2] = {{b0.x, b1.x - b0.x}, {b0.y, b1.y - b0.y}, {b0.z, b1.z - b0.z}};
            double light[2] = {1.0, 0.0};  // the light's spectrum in the cell, a + b t (1: no light)
            if (intensity) {
                const double i[3] = {intensity->x, intensity->y, intensity->z};
                light[0] = i[0] * basis[0][0] + i[1] * basis[1][0] + i[2] * basis[2][0];
                light[1] = i[0] * basis[0][1] + i[1] * basis[1][1] + i[2] * basis[2][1];
            }
            Cell& cell = cells_[j];
            for (int k = 0; k < 3; ++k)
                for (int c = 0; c < 3; ++c) {
                    const int e = 3 * k + c;
                    // (f + f' t)(b + b' t)(l + l' t): coefficients of t^0 .. t^3
                    const double p0 = film[k][0] * basis[c][0];
                    const double p1 = film[k][0] * basis[c][1] + film[k][1] * basis[c][0];
                    const double p2 = film[k][1] * basis[c][1];
                    const double a[4] = {p0 * light[0], p0 * light[1] + p1 * light[0], p1 * light[1] + p2 * light[0],
                                         p2 * light[1]};
                    cell.start[e / 4][e % 4] = float(start[e]);
                    for (int m = 0; m < 4; ++m) cell.b[m][e / 4][e % 4] = float(a[m] / (m + 1));
                    start[e] += a[0] + a[1] / 2 + a[2] / 3 + a[3] / 4;
                }
        }
        for (int e = 0; e < 9; ++e) whole_[e / 4][e % 4] = float(start[e]);
        end_nm_ = SpectralTables::kMinNm + float(cells);
    }

    // The integral from 380 nm to nm, entry by entry. (A band's ends are
    // often the range's: those need no cell.)
    void up_to(float nm, Entries& out) const {
        if (nm <= SpectralTables::kMinNm) {
            for (int v = 0; v < kVectors; ++v) out[v] = Lanes{};
            return;
        }
        if (nm >= end_nm_) {
            for (int v = 0; v < kVectors; ++v) out[v] = whole_[v];
            return;
        }
        const float x = std::clamp(nm, SpectralTables::kMinNm, end_nm_) - SpectralTables::kMinNm;
        const int j = std::min(int(x), int(cells_.size()) - 1);
        const float t = x - float(j);
        const Cell& cell = cells_[size_t(j)];
        for (int v = 0; v < kVectors; ++v)
            out[v] = cell.start[v] + t * (cell.b[0][v] + t * (cell.b[1][v] + t * (cell.b[2][v] + t * cell.b[3][v])));
    }

    std::vector<Cell> cells_;
    Entries whole_ = {};
    float end_nm_ = SpectralTables::kMaxNm;
};

class DispersionRuns {
  public:
    DispersionRuns() = default;
    // inverse_focus_per_m_by_nm: 1 / focus at every nm from 380 nm.
    explicit DispersionRuns(const std::vector<double>& inverse_focus_per_m_by_nm) {
        const std::vector<double>& k = inverse_focus_per_m_by_nm;
        if (k.size() < 2) return;
        lo_ = *std::min_element(k.begin(), k.end()), hi_ = *std::max_element(k.begin(), k.end());
        // The d line's plane, read linearly between the table's nm.
        const double d_at = kReferenceNm - double(SpectralTables::kMinNm);
        const size_t below = std::min(size_t(d_at), k.size() - 2);
        reference_ = k[below] + (d_at - double(below)) * (k[below + 1] - k[below]);
        // Split where the table turns (a step of 0 belongs to the stretch it is in).
        size_t first = 0;
        int direction = 0;
        for (size_t i = 0; i + 1 < k.size(); ++i) {
            const int step = k[i + 1] > k[i] ? 1 : k[i + 1] < k[i] ? -1 : 0;
            if (step != 0 && direction != 0 && step != direction) {
                add_run(k, first, i, direction);
                first = i;
            }
            if (step != 0) direction = step;
        }
        add_run(k, first, k.size() - 1, direction >= 0 ? 1 : -1);
    }

    bool fits() const { return !runs_.empty() && runs_.size() <= size_t(kMaxBandRuns); }
    double lowest() const { return lo_; }
    double highest() const { return hi_; }
    // The middle plane: the pencil's (ThinLensCamera::pencil).
    double middle() const { return 0.5 * (lo_ + hi_); }
    // The band rays' reference plane (thin_lens_bands.h): the d line's.
    // Any plane gives each wavelength its own camera's samples; this one
    // decides which wavelengths a split sample carries on a ray a pixel
    // away (those whose film points leave the pixel: the far ones), and at
    // the d line, near the middle of the film's response, they weigh least.
    // Against the planes' middle (483 nm): showcase 180x120 through
    // dgauss_abbe.dat, 64 spp, six seed pairs, relative RMSE 0.01657
    // against 0.01715 (RGB 0.01574); 555 nm 0.01658, 540 0.01659 (session 31).
    double reference() const { return reference_; }
    static constexpr double kReferenceNm = 587.56;  // Fraunhofer d (helium)

    // Where plane of focus k falls in each run: the wavelength where the
    // set {k' < k} ends in a rising run, or begins in a falling one.
    struct Ends {
        double k;
        float nm[kMaxBandRuns];
    };
    void ends_at(double k, Ends* out) const {
        out->k = k;
        for (size_t r = 0; r < runs_.size(); ++r)
            out->nm[r] = runs_[r].rising ? runs_[r].nm_where_reaches(k) : runs_[r].nm_where_passes(-k);
    }

    // The wavelengths whose 1 / focus lies in [k_lo, k_hi), into *out (needs fits()).
    void band_of(double k_lo, double k_hi, WavelengthBand* out) const {
        Ends lo, hi;
        ends_at(k_lo, &lo), ends_at(k_hi, &hi);
        band_between(lo, hi, out);
    }
    // The same from the ends at k_lo and k_hi (a split sample's rays share
    // theirs: one ray's k_hi is the next one's k_lo).
    void band_between(const Ends& lo, const Ends& hi, WavelengthBand* out) const {
        out->count = 0;
        for (size_t r = 0; r < runs_.size(); ++r) {
            // rising: {k < x} is [start, at(x)), the band [at(k_lo), at(k_hi));
            // falling (values -k): {k < x} is (at(-x), end], the band (at(-k_hi), at(-k_lo)]
            const float from = runs_[r].rising ? lo.nm[r] : hi.nm[r], to = runs_[r].rising ? hi.nm[r] : lo.nm[r];
            if (to > from) {
                out->from_nm[out->count] = from, out->to_nm[out->count] = to;
                ++out->count;
            }
        }
    }

  private:
    // A stretch of the table, its values rising (k, or -k where k falls).
    struct Run {
        float first_nm;
        bool rising;
        std::vector<double> value;
        // Where to start looking: guide[g] is the first node at or past the
        // start of the g-th of guide.size() equal steps over the values (a
        // search per band's end was a tenth of a render's time, perf).
        std::vector<int> guide;
        double guide_scale = 0.0;

        void build_guide() {
            const double lo = value.front(), hi = value.back();
            if (!(hi > lo)) return;
            guide.resize(4 * value.size());
            guide_scale = double(guide.size()) / (hi - lo);
            for (size_t g = 0; g < guide.size(); ++g)
                guide[g] = int(std::lower_bound(value.begin(), value.end(), lo + double(g) / guide_scale) -
                               value.begin());
        }
        // A node near the first at or past x (value[0] < x <= value.back()).
        size_t near(double x) const {
            const size_t g = std::min(size_t((x - value.front()) * guide_scale), guide.size() - 1);
            return size_t(guide[g]);
        }
        // The wavelength where value first reaches x (value < x before it).
        float nm_where_reaches(double x) const {
            if (!(x > value.front())) return first_nm;
            if (x > value.back()) return at(value.size(), x);
            size_t j = near(x);
            while (j > 0 && value[j - 1] >= x) --j;
            while (value[j] < x) ++j;
            return at(j, x);
        }
        // The wavelength where value first passes x (value <= x before it).
        float nm_where_passes(double x) const {
            if (x < value.front()) return first_nm;
            if (!(x < value.back())) return at(value.size(), x);
            size_t j = near(x);
            while (j > 0 && value[j - 1] > x) --j;
            while (value[j] <= x) ++j;
            return at(j, x);
        }
        // Between nodes j - 1 and j (value[j - 1] < value[j] there), linear.
        float at(size_t j, double x) const {
            if (j == 0) return first_nm;
            if (j == value.size()) return first_nm + float(value.size() - 1);
            const double t = (x - value[j - 1]) / (value[j] - value[j - 1]);
            return float(double(first_nm) + double(j - 1) + t);
        }
    };

    void add_run(const std::vector<double>& k, size_t first, size_t last, int direction) {
        Run run{SpectralTables::kMinNm + float(first), direction > 0, {}, {}, 0.0};
        for (size_t i = first; i <= last; ++i) run.value.push_back(direction > 0 ? k[i] : -k[i]);
        run.build_guide();
        runs_.push_back(std::move(run));
    }

    std::vector<Run> runs_;
    double lo_ = 0.0, hi_ = 0.0, reference_ = 0.0;
};

}  // namespace lc
