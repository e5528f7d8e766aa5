// PCG32's outputs several states at a time (Pcg32::fill_u32): each kernel
// steps k states a step apart by the LCG's k-step map, s -> A s + C with
// A = M^k and C = inc (M^(k-1) + ... + M + 1), so the multiplications run
// side by side instead of in one chain, and every kernel gives the same
// numbers, in order, as next_u32 one at a time (integer arithmetic only).
// The AVX-512 kernel steps 16 states in two registers (vpmullq, AVX-512DQ);
// the AVX2 kernel the same 16 in four (the 64-bit multiply composed of
// 32-bit ones, by hand); the portable kernel 4 in general registers.
#include "rng.h"

#include <immintrin.h>

#include <cstring>

#include "cpu_kernels.h"

namespace lc {
namespace {

uint64_t step(uint64_t state, uint64_t inc) { return state * kPcg32Multiplier + inc; }

// M^j and S_j = M^(j-1) + ... + M + 1 for j = 0..kSteps: lane j starts at
// M^j s + S_j inc, all lanes at once instead of a chain of steps, and a
// leap of k steps is A = M^k, C = S_k inc (every kernel's).
// Set-up was most of a call's time at a pixel's 64 to 128 numbers (perf).
constexpr int kSteps = 16;
struct StepPowers {
    uint64_t power[kSteps + 1], sum[kSteps + 1];
};
constexpr StepPowers step_powers() {
    StepPowers p{};
    p.power[0] = 1, p.sum[0] = 0;
    for (int j = 1; j <= kSteps; ++j)
        p.power[j] = p.power[j - 1] * kPcg32Multiplier, p.sum[j] = p.sum[j - 1] * kPcg32Multiplier + 1;
    return p;
}
constexpr StepPowers kStepPowers = step_powers();

// The rest one step at a time, from the state after the leaps.
void finish(uint64_t* state, uint64_t inc, uint32_t* out, int first, int n) {
    for (int i = first; i < n; ++i) out[i] = pcg32_output(*state), *state = step(*state, inc);
}

void fill_portable(uint64_t* state, uint64_t inc, uint32_t* out, int n) {
    constexpr int kLanes = 4;
    uint64_t lane[kLanes];
    for (int j = 0; j < kLanes; ++j) lane[j] = *state * kStepPowers.power[j] + inc * kStepPowers.sum[j];
    const uint64_t a = kStepPowers.power[kLanes], c = inc * kStepPowers.sum[kLanes];
    int i = 0;
    for (; i + kLanes <= n; i += kLanes)
        for (int j = 0; j < kLanes; ++j) out[i + j] = pcg32_output(lane[j]), lane[j] = lane[j] * a + c;
    *state = lane[0];  // the state after i steps
    finish(state, inc, out, i, n);
}

// Eight states in a vector (GCC's vector extension: one zmm register), for the
// AVX-512 kernel; the AVX2 kernel below has its own registers of four.
typedef uint64_t States8 __attribute__((vector_size(64)));
typedef uint32_t Outputs8 __attribute__((vector_size(32)));

[[gnu::always_inline]] inline Outputs8 outputs8(States8 lane) {
    const Outputs8 xorshifted = __builtin_convertvector(((lane >> 18) ^ lane) >> 27, Outputs8);
    const Outputs8 rot = __builtin_convertvector(lane >> 59, Outputs8);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
}

// Two registers of eight states, sixteen apart in all, stepped side by side:
// the two chains of multiplications overlap their latencies.
[[gnu::always_inline]] inline void fill_body8(uint64_t* state, uint64_t inc, uint32_t* out, int n) {
    constexpr int kLanes = 8;
    States8 power, sum;
    for (int j = 0; j < kLanes; ++j) power[j] = kStepPowers.power[j], sum[j] = kStepPowers.sum[j];
    States8 low = *state * power + inc * sum;  // states i .. i + 7
    States8 high = low * kStepPowers.power[kLanes] + inc * kStepPowers.sum[kLanes];  // i + 8 .. i + 15
    const uint64_t a = kStepPowers.power[2 * kLanes], c = inc * kStepPowers.sum[2 * kLanes];
    int i = 0;
    for (; i + 2 * kLanes <= n; i += 2 * kLanes) {
        const Outputs8 first = outputs8(low), second = outputs8(high);
        std::memcpy(out + i, &first, sizeof first);
        std::memcpy(out + i + kLanes, &second, sizeof second);
        low = low * a + c, high = high * a + c;
    }
    if (i + kLanes <= n) {
        const Outputs8 first = outputs8(low);
        std::memcpy(out + i, &first, sizeof first);
        i += kLanes;
        low = high;
    }
    *state = low[0];  // the state after i steps
    finish(state, inc, out, i, n);
}

// AVX2 has no 64-bit multiply: a x mod 2^64 = lo(a) lo(x) + ((lo(a) hi(x) +
// hi(a) lo(x)) << 32), three vpmuludq. Written with intrinsics: GCC's
// composition of fill_body8's 64-byte vectors spilled them to the stack and
// reloaded them at once (store-forwarding stalls; the PCG fill was the
// largest item of an empty scene's thin-lens render on an AMD EPYC, perf).
struct Multiplier4 {
    __m256i lo, hi;  // a's low and high 32 bits, in each 64-bit lane
    [[gnu::target("avx2")]] explicit Multiplier4(uint64_t a)
        : lo(_mm256_set1_epi64x(int64_t(a & 0xffffffffu))), hi(_mm256_set1_epi64x(int64_t(a >> 32))) {}
};

// a x + c in each 64-bit lane, mod 2^64.
[[gnu::target("avx2")]] inline __m256i multiply_add4(__m256i x, const Multiplier4& a, __m256i c) {
    const __m256i low = _mm256_mul_epu32(x, a.lo);
    const __m256i cross = _mm256_add_epi64(_mm256_mul_epu32(_mm256_srli_epi64(x, 32), a.lo), _mm256_mul_epu32(x, a.hi));
    return _mm256_add_epi64(_mm256_add_epi64(low, _mm256_slli_epi64(cross, 32)), c);
}

// The low 32 bits of each 64-bit lane of a (states 0-3) and b (4-7), in order.
[[gnu::target("avx2")]] inline __m256i low_halves8(__m256i a, __m256i b) {
    const __m256 mixed = _mm256_shuffle_ps(_mm256_castsi256_ps(a), _mm256_castsi256_ps(b), _MM_SHUFFLE(2, 0, 2, 0));
    return _mm256_permute4x64_epi64(_mm256_castps_si256(mixed), _MM_SHUFFLE(3, 1, 2, 0));
}

// pcg32_output of eight states (a: 0-3, b: 4-7), into out[0, 8).
[[gnu::target("avx2")]] inline void outputs8_avx2(__m256i a, __m256i b, uint32_t* out) {
    const __m256i xorshifted = low_halves8(_mm256_srli_epi64(_mm256_xor_si256(_mm256_srli_epi64(a, 18), a), 27),
                                           _mm256_srli_epi64(_mm256_xor_si256(_mm256_srli_epi64(b, 18), b), 27));
    const __m256i rot = low_halves8(_mm256_srli_epi64(a, 59), _mm256_srli_epi64(b, 59));
    const __m256i left = _mm256_and_si256(_mm256_sub_epi32(_mm256_set1_epi32(32), rot), _mm256_set1_epi32(31));
    const __m256i rotated = _mm256_or_si256(_mm256_srlv_epi32(xorshifted, rot), _mm256_sllv_epi32(xorshifted, left));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out), rotated);
}

[[gnu::target("avx2")]] void fill_avx2(uint64_t* state, uint64_t inc, uint32_t* out, int n) {
    constexpr int kLanes = 16;  // four registers of four states, i .. i + 15
    __m256i lane[4];
    for (int r = 0; r < 4; ++r) {
        alignas(32) uint64_t start[4];
        for (int j = 0; j < 4; ++j)
            start[j] = *state * kStepPowers.power[4 * r + j] + inc * kStepPowers.sum[4 * r + j];
        lane[r] = _mm256_load_si256(reinterpret_cast<const __m256i*>(start));
    }
    const Multiplier4 a(kStepPowers.power[kLanes]);
    const __m256i c = _mm256_set1_epi64x(int64_t(inc * kStepPowers.sum[kLanes]));
    int i = 0;
    for (; i + kLanes <= n; i += kLanes) {
        outputs8_avx2(lane[0], lane[1], out + i);
        outputs8_avx2(lane[2], lane[3], out + i + 8);
        for (__m256i& l : lane) l = multiply_add4(l, a, c);
    }
    if (i + 8 <= n) {
        outputs8_avx2(lane[0], lane[1], out + i);
        i += 8;
        lane[0] = lane[2];
    }
    *state = uint64_t(_mm256_extract_epi64(lane[0], 0));  // the state after i steps
    finish(state, inc, out, i, n);
}

[[gnu::target("avx512f,avx512dq,avx512vl")]] void fill_avx512(uint64_t* state, uint64_t inc, uint32_t* out, int n) {
    fill_body8(state, inc, out, n);
}

}  // namespace

bool rng_kernel_available(RngKernel kernel) {
    switch (kernel) {
        case RngKernel::Avx2: return __builtin_cpu_supports("avx2");
        case RngKernel::Avx512:
            return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
                   __builtin_cpu_supports("avx512vl");
        default: return true;
    }
}

const char* rng_kernel_name(RngKernel kernel) {
    switch (kernel) {
        case RngKernel::Avx2: return "avx2";
        case RngKernel::Avx512: return "avx512";
        default: return "portable";
    }
}

RngKernel fastest_rng_kernel() {
    static const RngKernel best = fastest_available(kRngKernels, rng_kernel_available);
    return best;
}

void pcg32_fill(RngKernel kernel, uint64_t* state, uint64_t inc, uint32_t* out, int n) {
    switch (kernel) {
        case RngKernel::Avx512: return fill_avx512(state, inc, out, n);
        case RngKernel::Avx2: return fill_avx2(state, inc, out, n);
        default: return fill_portable(state, inc, out, n);
    }
}

}  // namespace lc
