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
        state_ = old * kMultiplier + inc_;
        return output(old);
    }

    // The next n outputs of next_u32, in order, the state then n steps on. Four
    // states a step apart each leap four steps at a time (the LCG's k-step map
    // is again affine: A = M^4, C = inc (M^3 + M^2 + M + 1)), so four
    // multiplications run side by side instead of one chain of n.
    void fill_u32(uint32_t* out, int n) {
        uint64_t lane[4];
        for (uint64_t& s : lane) s = state_, state_ = state_ * kMultiplier + inc_;
        const uint64_t m2 = kMultiplier * kMultiplier, leap_multiplier = m2 * m2;
        const uint64_t leap_increment = inc_ * (m2 * kMultiplier + m2 + kMultiplier + 1);
        int i = 0;
        for (; i + 4 <= n; i += 4)
            for (int j = 0; j < 4; ++j) out[i + j] = output(lane[j]), lane[j] = lane[j] * leap_multiplier + leap_increment;
        // lane[0] is now the state after i steps; the rest one at a time
        state_ = lane[0];
        for (; i < n; ++i) out[i] = next_u32();
    }

    // Uniform in [0, 1): 24 random bits, so the result is exactly representable
    // and never rounds up to 1.
    float next_float() { return to_float(next_u32()); }
    static float to_float(uint32_t bits) { return float(bits >> 8) * 0x1p-24f; }

    // Uniform integer in [0, n) without modulo bias worth worrying about for n << 2^32.
    uint32_t next_below(uint32_t n) { return below(next_u32(), n); }
    static uint32_t below(uint32_t bits, uint32_t n) { return uint32_t((uint64_t(bits) * n) >> 32); }

  private:
    static constexpr uint64_t kMultiplier = 6364136223846793005ULL;

    // PCG's XSH RR output of a state.
    static uint32_t output(uint64_t old) {
        const uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
        const uint32_t rot = uint32_t(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
    }

    uint64_t state_, inc_;
};

}  // namespace lc
