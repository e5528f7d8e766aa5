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
// A ray's set S is a band of planes of focus [k_lo, k_hi) (1 / focus,
// 1/m, the thin lens's table, linear between whole nm): the wavelengths
// focused there. FocusBandIntegrals holds such a map's integral over the
// wavelengths focused below any k, exact for the per-nm tables read
// linearly (the integrand is a product of two or three linear functions
// within a nm: a polynomial, integrated in closed form); a band's map is
// the difference at its ends.
//
// DispersionRuns turns a band of planes of focus into the wavelengths
// themselves (a monochromatic light's line needs them): one interval per
// stretch of the table that rises or falls (a singlet's has one; an
// achromat's, whose focus turns back, two).
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

// A set of wavelengths: count intervals [from_nm, to_nm].
struct WavelengthBand {
    int count = 0;
    float from_nm[kMaxBandRuns], to_nm[kMaxBandRuns];
};

// The film's reading over the wavelengths whose plane of focus lies below
// k, F(k) = ∫_{λ: k(λ) < k} film_k B_c [I] dλ, for the maps above: of the
// basis (table 0) and of each light (table 1 + l). A ray carrying planes of
// focus [k_lo, k_hi) reads F(k_hi) - F(k_lo) (a band given by its planes
// of focus, not by wavelengths: no wavelength is looked up). With k(λ)
// linear within each nm and the integrand a cubic there, F is a quartic in
// k between consecutive values of the table (over each such interval every
// monotone stretch of k(λ) has one nm cell in it), so F is exact, as the
// per-nm integrals were. (Session 36: a band's ends found in nm first, per
// stretch of the table, then integrated per nm, were a fifth of a
// dispersive thin-lens render, perf.)
class FocusBandIntegrals {
  public:
    // inverse_focus_per_m_by_nm: 1 / focus at every nm from 380 nm (the
    // spectral tables' grid); light_intensities: the scene's lights' RGB.
    FocusBandIntegrals(const SpectralTables& t, const std::vector<Vec3f>& light_intensities,
                       const std::vector<double>& inverse_focus_per_m_by_nm);

    // Where F is read at k: the interval holding k and how far into it,
    // shared by every table.
    struct End {
        int interval;  // -1: at or below the lowest plane (F = 0); intervals(): at or above the highest (F whole)
        float s;       // [0, 1) within the interval
    };
    End end_at(double k) const {
        if (!(k > breaks_.front())) return {-1, 0.0f};
        if (k >= breaks_.back()) return {intervals(), 0.0f};
        const size_t g = std::min(size_t((k - breaks_.front()) * guide_scale_), guide_.size() - 1);
        size_t i = size_t(guide_[g]);
        while (breaks_[i + 1] <= k) ++i;
        return {int(i), float((k - breaks_[i]) * inverse_width_[i])};
    }

    // The last end a caller's apply read, kept by the caller across a
    // packet's rays for one table: a split sample's two rays, one after the
    // other, meet at one plane (the first's band ends where the second's
    // begins), so the second reads it from here.
    struct LastRead;

    // Table table's map over [lo, hi) applied to a colour: out_k = sum_c map[k][c] colour_c.
    void apply(int table, const End& lo, const End& hi, float c0, float c1, float c2, float out[3],
               LastRead* last = nullptr) const {
        Entries from, to;
        read(table, lo, from, last);
        read(table, hi, to, last);
        const Lanes mapped = (to[0] - from[0]) * c0 + (to[1] - from[1]) * c1 + (to[2] - from[2]) * c2;
        out[0] = mapped[0], out[1] = mapped[1], out[2] = mapped[2];
    }

    int intervals() const { return int(breaks_.size()) - 1; }

    // The film's response to white carried by the planes of focus below k
    // (below true) or at and above it, as a share of the whole spectrum's,
    // the most of the three channels': read from a table of kShareSteps
    // steps (nearest), for roulette probabilities (BandRoulette), not for a
    // ray's reading.
    float white_share(double k, bool below) const {
        const double at = (k - breaks_.front()) * share_steps_per_k_;
        const size_t i = size_t(std::clamp(at + 0.5, 0.0, double(kShareSteps)));
        return (below ? share_below_ : share_above_)[i];
    }

  private:
    static constexpr int kShareSteps = 256;
    void build_white_shares();

    // A map's columns, the film's three channels k of basis colour c in
    // vector c's lanes 0-2 (lane 3 zero), so that a map applies in three
    // vector products (GCC's vector extension: written as floats, the
    // entries' loop stayed scalar, a fifth of a render, perf, session 29).
    typedef float Lanes __attribute__((vector_size(16)));
    static constexpr int kVectors = 3;
    using Entries = Lanes[kVectors];
    // F over one interval for one table: c[0] + s (c[1] + s (c[2] + s (c[3] + s c[4]))).
    struct Cell {
        Entries c[5];
    };
    struct Sum {
        Entries e;
    };

  public:
    struct LastRead {
        End at{-1, 0.0f};  // an end inside the table once anything is kept
        Entries entries;
    };

  private:
    void read(int table, const End& at, Entries& out, LastRead* last) const {
        if (at.interval < 0) {
            for (int v = 0; v < kVectors; ++v) out[v] = Lanes{};
            return;
        }
        if (at.interval >= intervals()) {
            for (int v = 0; v < kVectors; ++v) out[v] = whole_[size_t(table)].e[v];
            return;
        }
        if (last && at.interval == last->at.interval && at.s == last->at.s) {
            for (int v = 0; v < kVectors; ++v) out[v] = last->entries[v];
            return;
        }
        const Cell& cell = cells_[size_t(at.interval) * size_t(tables_) + size_t(table)];
        const float s = at.s;
        for (int v = 0; v < kVectors; ++v)
            out[v] = cell.c[0][v] + s * (cell.c[1][v] + s * (cell.c[2][v] + s * (cell.c[3][v] + s * cell.c[4][v])));
        if (last) {
            last->at = at;
            for (int v = 0; v < kVectors; ++v) last->entries[v] = out[v];
        }
    }

    int tables_ = 0;
    std::vector<double> breaks_;         // the table's values, sorted, each once
    std::vector<double> inverse_width_;  // 1 / (breaks_[i + 1] - breaks_[i])
    // guide_[g]: the interval holding the start of the g-th of guide_.size()
    // equal steps over the breaks (so a search from it takes a step or none).
    std::vector<int> guide_;
    double guide_scale_ = 0.0;
    std::vector<Cell> cells_;  // [interval * tables_ + table]
    std::vector<Sum> whole_;  // F at and above the highest plane, per table
    std::vector<float> share_below_, share_above_;  // white_share at kShareSteps + 1 planes over the breaks
    double share_steps_per_k_ = 0.0;
};

// Russian roulette on the ray a pixel away of a split sample of a band
// render (render_tile_bands.h; through the lens system that ray is traced
// through the lens and the scene, and such rays were about a fifth of the
// band render's time, session 47). A sample split once, its own ray
// carrying band A and the ray a pixel away band B of the whole spectrum W
// (maps M_A + M_B = W), is worth M_A c_own + M_B c_away =
// W c_own + M_B (c_away - c_own): its own ray's colour through the whole
// spectrum, corrected by the difference the other pixel makes in band B.
// With probability q the correction is traced and weighed 1 / q, else the
// sample is shaded whole from its own ray: the same value on average, and
// the difference is zero wherever both rays see the same colour (all but
// the image's edges). Traced, the own ray's map is (M_A + (q - 1) W) / q and the
// other's M_B / q (BandRays' entry_scale and entry_whole_part). q is
// kGain times the most a channel of white's response lies in band B, at
// most 1 (the variance a sample adds is (1 / q - 1) |M_B (c_away - c_own)|^2,
// the time it saves goes as 1 - q): a band at the spectrum's dim ends is
// rarely traced.
struct BandRoulette {
    // Showcase 180x120 through dgauss_abbe.dat, 64 spp, against no roulette
    // (session 48): gain 1 took 0.889 of the render time (best of 15 renders)
    // for 1.007 of the variance (six seed pairs), 0.75 0.870 for 1.028, 0.5
    // 0.847 for 1.077; 0.75 and 1 are equally efficient (time x variance
    // 0.894, 0.895; 0.5 0.912).
    static constexpr float kGain = 0.75f;
    const FocusBandIntegrals* integrals;

    float probability(double k_split, bool away_below) const {
        return std::min(1.0f, kGain * integrals->white_share(k_split, away_below));
    }
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

    // The wavelengths whose 1 / focus lies in [k_lo, k_hi), into *out (needs fits()).
    void band_of(double k_lo, double k_hi, WavelengthBand* out) const {
        out->count = 0;
        for (const Run& run : runs_) {
            // Where plane of focus x falls in the run: the wavelength where the
            // set {k < x} ends in a rising run, or begins in a falling one.
            // rising: {k < x} is [start, at(x)), the band [at(k_lo), at(k_hi));
            // falling (values -k): {k < x} is (at(-x), end], the band (at(-k_hi), at(-k_lo)]
            const float from = run.rising ? run.nm_where_reaches(k_lo) : run.nm_where_passes(-k_hi);
            const float to = run.rising ? run.nm_where_reaches(k_hi) : run.nm_where_passes(-k_lo);
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

// The bands a batch's rays carry (render_tile_bands.h): ray i the
// wavelengths whose 1 / focus lies in [k_lo[i], k_hi[i]).
struct RayFocusBands {
    const FocusBandIntegrals* integrals;
    const DispersionRuns* runs;  // for the wavelengths themselves (a monochromatic light's line)
    const double* k_lo;
    const double* k_hi;
    const float* whole_part;  // ray i's map is its band's plus whole_part[i] times the whole spectrum's
};

}  // namespace lc
