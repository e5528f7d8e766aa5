// Counter-based random numbers: every pixel gets its own stream derived from
// (seed, pixel index), so an image does not depend on thread scheduling.
#pragma once

#include <cstdint>

namespace lc {

// SplitMix64 finaliser (Steele et al. 2014): a strong 64-bit mixing function.
inline uint64_t mix64(uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

// PCG32's LCG multiplier (O'Neill 2014).
constexpr uint64_t kPcg32Multiplier = 6364136223846793005ULL;

// PCG's XSH RR output of a state.
inline uint32_t pcg32_output(uint64_t old) {
    const uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
    const uint32_t rot = uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
}

// The kernels that draw many outputs at once (rng_lanes.cpp), one instruction
// set each: the same numbers on every one.
enum class RngKernel : int { Portable = 0, Avx2 = 1, Avx512 = 2 };
constexpr RngKernel kRngKernels[] = {RngKernel::Portable, RngKernel::Avx2, RngKernel::Avx512};
bool rng_kernel_available(RngKernel kernel);
const char* rng_kernel_name(RngKernel kernel);
RngKernel fastest_rng_kernel();

// out[0, n): the outputs of PCG32 (increment inc) from *state on, which is then n steps further.
void pcg32_fill(RngKernel kernel, uint64_t* state, uint64_t inc, uint32_t* out, int n);

// PCG32 (O'Neill 2014), seeded from a hash of the stream's coordinates.
class Pcg32 {
  public:
    Pcg32(uint64_t seed, uint64_t stream, uint64_t dimension = 0) {
        state_ = 0;
        inc_ = (mix64(stream ^ (dimension * 0x9e3779b97f4a7c15ULL)) << 1u) | 1u;
        next_u32();
        state_ += mix64(seed + 0x632be59bd9b4e019ULL);
        next_u32();
    }

    uint32_t next_u32() {
        uint64_t old = state_;
        state_ = old * kPcg32Multiplier + inc_;
        return pcg32_output(old);
    }

    // The next n outputs of next_u32, in order, the state then n steps on:
    // several states at a time (rng_lanes.cpp), not one chain of n multiplications.
    void fill_u32(uint32_t* out, int n, RngKernel kernel = fastest_rng_kernel()) {
        pcg32_fill(kernel, &state_, inc_, out, n);
    }

    // Uniform in [0, 1): 24 random bits, so the result is exactly representable
    // and never rounds up to 1.
    float next_float() { return to_float(next_u32()); }
    static float to_float(uint32_t bits) { return float(bits >> 8) * 0x1p-24f; }

    // Uniform integer in [0, n) without modulo bias worth worrying about for n << 2^32.
    uint32_t next_below(uint32_t n) { return below(next_u32(), n); }
    static uint32_t below(uint32_t bits, uint32_t n) { return uint32_t((uint64_t(bits) * n) >> 32); }

  private:
    uint64_t state_, inc_;
};

}  // namespace lc
