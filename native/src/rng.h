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
        state_ = old * 6364136223846793005ULL + inc_;
        uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
        uint32_t rot = uint32_t(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
    }

    // Uniform in [0, 1): 24 random bits, so the result is exactly representable
    // and never rounds up to 1.
    float next_float() { return float(next_u32() >> 8) * 0x1p-24f; }

    // Uniform integer in [0, n) without modulo bias worth worrying about for n << 2^32.
    uint32_t next_below(uint32_t n) { return uint32_t((uint64_t(next_u32()) * n) >> 32); }

  private:
    uint64_t state_, inc_;
};

}  // namespace lc
