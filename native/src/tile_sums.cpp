#include "tile_sums.h"

#include "cpu_kernels.h"

namespace lc {
namespace {

// Four doubles (channels r, g, b and an unused fourth): one AVX register, two
// SSE2 ones on the portable build. GCC's vector extension: no intrinsics, so
// one body serves every clone.
typedef double Channels __attribute__((vector_size(32)));
typedef float ChannelsF __attribute__((vector_size(16)));

// radiance[j]'s three floats widened to double, in one conversion (not
// three); the fourth lane holds radiance[j + 1].x, unused, except for the
// array's last sample, which must not be read past.
[[gnu::always_inline]] inline Channels widened(const Vec3f* radiance, int j, int n) {
    static_assert(sizeof(Vec3f) == 3 * sizeof(float), "x, y, z packed");
    ChannelsF c;
    if (j + 1 < n) {
        __builtin_memcpy(&c, radiance + j, sizeof(c));
    } else {
        c = ChannelsF{radiance[j].x, radiance[j].y, radiance[j].z, 0.0f};
    }
    return __builtin_convertvector(c, Channels);
}

}  // namespace

LC_BUILT_PER_ISA void add_tile_samples(int n, const size_t* slot, const Vec3f* radiance, const float* weight,
                                       double* sums, double* squares) {
    for (int j = 0; j < n;) {
        const size_t pixel = slot[j], at = 3 * pixel;
        Channels sum = {sums[at], sums[at + 1], sums[at + 2], 0.0};
        Channels square = {0.0, 0.0, 0.0, 0.0};
        if (squares) square = Channels{squares[at], squares[at + 1], squares[at + 2], 0.0};
        for (; j < n && slot[j] == pixel; ++j) {
            const Channels v = widened(radiance, j, n) * double(weight[j]);
            sum += v;
            square += v * v;  // no contraction (-ffp-contract=off): a product, then a sum
        }
        sums[at] = sum[0], sums[at + 1] = sum[1], sums[at + 2] = sum[2];
        if (squares) squares[at] = square[0], squares[at + 1] = square[1], squares[at + 2] = square[2];
    }
}

}  // namespace lc
