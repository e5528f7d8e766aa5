// laid_out's copy (lens_trace.h): a batch's lanes' indices, each lane's row
// of the dispersion table read side by side, written surface by surface.
// Four lanes' four surfaces at a time, transposed in registers: copied one
// value at a time it cost about 14 ns a spectral lens-system sample (24
// values a sample, two traced wavelengths) on an AVX2 Zen 3, perf, session 40.
#include "lens/lens_trace.h"

#include "cpu_kernels.h"

namespace lc {
namespace {

// Four doubles: one AVX register, two SSE2 ones on the portable build
// (GCC's vector extension: one body serves every clone).
typedef double Four __attribute__((vector_size(32)));
typedef long long FourIndex __attribute__((vector_size(32)));

[[gnu::always_inline]] inline Four load4(const double* p) {
    Four v;
    __builtin_memcpy(&v, p, sizeof v);
    return v;
}
[[gnu::always_inline]] inline void store4(double* p, Four v) { __builtin_memcpy(p, &v, sizeof v); }

// out[s * kLensBatch + i] = table[row[i] * stride + s] for surfaces [0, stride),
// stride a multiple of 4.
[[gnu::always_inline]] inline void transpose_rows(const double* table, size_t stride, const int32_t* row, double* out) {
    for (int i = 0; i < kLensBatch; i += 4) {
        const double* r0 = table + size_t(row[i]) * stride;
        const double* r1 = table + size_t(row[i + 1]) * stride;
        const double* r2 = table + size_t(row[i + 2]) * stride;
        const double* r3 = table + size_t(row[i + 3]) * stride;
        for (size_t s = 0; s < stride; s += 4) {
            const Four a = load4(r0 + s), b = load4(r1 + s), c = load4(r2 + s), d = load4(r3 + s);
            // Pairs of lanes interleaved, then the halves swapped: the 4 x 4 transpose.
            const Four ab_even = __builtin_shuffle(a, b, FourIndex{0, 4, 2, 6});
            const Four ab_odd = __builtin_shuffle(a, b, FourIndex{1, 5, 3, 7});
            const Four cd_even = __builtin_shuffle(c, d, FourIndex{0, 4, 2, 6});
            const Four cd_odd = __builtin_shuffle(c, d, FourIndex{1, 5, 3, 7});
            double* at = out + s * kLensBatch + size_t(i);
            store4(at, __builtin_shuffle(ab_even, cd_even, FourIndex{0, 1, 4, 5}));
            store4(at + kLensBatch, __builtin_shuffle(ab_odd, cd_odd, FourIndex{0, 1, 4, 5}));
            store4(at + 2 * kLensBatch, __builtin_shuffle(ab_even, cd_even, FourIndex{2, 3, 6, 7}));
            store4(at + 3 * kLensBatch, __builtin_shuffle(ab_odd, cd_odd, FourIndex{2, 3, 6, 7}));
        }
    }
}

}  // namespace

LC_BUILT_PER_ISA void lay_out_glass_lanes(const LensDispersion& d, const int32_t* row, double* eta_lanes,
                                          double* bends_at_lanes) {
    static_assert(kLensBatch % 4 == 0, "whole groups of four lanes");
    transpose_rows(d.eta.data(), d.row_stride, row, eta_lanes);
    if (d.any_some) transpose_rows(d.bends_at.data(), d.row_stride, row, bends_at_lanes);
}

}  // namespace lc
