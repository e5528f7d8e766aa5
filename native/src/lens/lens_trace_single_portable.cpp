// The batch lens trace in single precision for any x86-64 (lens_trace.h,
// LensTracePrecision): the template of lens_trace_lanes.h over one float lane,
// so that every kernel does the same float operations in the same order and
// gives the same bits. The reference the SIMD kernels are tested against.
#include <cmath>
#include <cstdint>

#include "lens/lens_trace.h"

namespace lc::portable_single {

struct M1 {
    bool v;

    static M1 load(const bool* p) { return {*p}; }
    void store(bool* p) const { *p = v; }
};

struct F1 {
    static constexpr int kLanes = 1;
    using Scalar = float;
    float v;

    F1() = default;
    explicit F1(double x) : v(float(x)) {}
    static F1 of(float x) {
        F1 f;
        f.v = x;
        return f;
    }
    static F1 load(const double* p) { return of(float(*p)); }
    void store(double* p) const { *p = double(v); }
};

inline F1 operator+(F1 a, F1 b) { return F1::of(a.v + b.v); }
inline F1 operator-(F1 a, F1 b) { return F1::of(a.v - b.v); }
inline F1 operator*(F1 a, F1 b) { return F1::of(a.v * b.v); }
inline F1 operator/(F1 a, F1 b) { return F1::of(a.v / b.v); }
inline F1 operator-(F1 a) { return F1::of(-a.v); }
inline F1 sqrt(F1 a) { return F1::of(std::sqrt(a.v)); }
// a * b + c, rounded once: the SIMD kernels' fused multiply-add, bit for bit
inline F1 mul_add(F1 a, F1 b, F1 c) { return F1::of(std::fma(a.v, b.v, c.v)); }
inline F1 copysign(F1 magnitude, F1 sign) { return F1::of(std::copysign(magnitude.v, sign.v)); }
// a > b ? a : b, as the SIMD max instruction
inline F1 max(F1 a, F1 b) { return F1::of(a.v > b.v ? a.v : b.v); }
// a < b ? a : b, as the SIMD min instruction
inline F1 min(F1 a, F1 b) { return F1::of(a.v < b.v ? a.v : b.v); }

inline M1 operator<(F1 a, F1 b) { return {a.v < b.v}; }
inline M1 operator>(F1 a, F1 b) { return {a.v > b.v}; }
inline M1 operator>=(F1 a, F1 b) { return {a.v >= b.v}; }
inline M1 operator!=(F1 a, F1 b) { return {a.v != b.v}; }
inline M1 not_greater(F1 a, F1 b) { return {!(a.v > b.v)}; }

inline M1 operator&(M1 a, M1 b) { return {a.v && b.v}; }
inline M1 operator|(M1 a, M1 b) { return {a.v || b.v}; }
inline bool any(M1 m) { return m.v; }
// m ? a : b
inline F1 select(M1 m, F1 a, F1 b) { return m.v ? a : b; }
// m ? min(a, b) : a
inline F1 min_where(M1 m, F1 a, F1 b) { return m.v ? min(a, b) : a; }

}  // namespace lc::portable_single

#include "lens/lens_trace_lanes.h"

namespace lc {

void trace_from_film_batch_single_portable(const std::vector<LensElement>& elements, LaneGlass glass,
                                           LensRayBatch* b) {
    if (glass.dispersion == nullptr)
        trace_from_film_lanes<portable_single::F1, portable_single::M1, false>(elements.data(), elements.size(),
                                                                               glass, b);
    else
        trace_from_film_lanes<portable_single::F1, portable_single::M1, true>(elements.data(), elements.size(),
                                                                              glass, b);
}

void trace_from_film_batch_single_margins_portable(const std::vector<LensElement>& elements, LensRayBatch* b,
                                                    double* margin) {
    trace_from_film_lanes<portable_single::F1, portable_single::M1, false, true>(
        elements.data(), elements.size(), LaneGlass{nullptr, nullptr}, b, margin);
}

}  // namespace lc
