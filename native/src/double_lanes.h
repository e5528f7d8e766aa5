// Four lanes of doubles and their masks (GCC's vector extension: a mask is
// all ones where true), for lane loops GCC will not vectorise written per
// sample: bools beside doubles, or a comparison it may not evaluate
// unconditionally (-ftrapping-math). Built in a function compiled per
// instruction set (LC_BUILT_PER_ISA), they take its widest registers. The
// operations are IEEE's, so a lane gives the bits the per-sample code did.
#pragma once

#include <cstdint>
#include <cstring>

namespace lc {

typedef double Double4 __attribute__((vector_size(32)));
typedef long long Mask4 __attribute__((vector_size(32)));
typedef signed char Byte4 __attribute__((vector_size(4)));  // four bools' bytes

// Lanes [first, first + 4) of values, those at or past n read as 0.
inline Double4 lanes_of(const double* values, int first, int n) {
    Double4 v{};
    if (first + 4 <= n) std::memcpy(&v, values + first, sizeof v);
    else
        for (int l = 0; first + l < n; ++l) v[l] = values[first + l];
    return v;
}

// Lanes [first, first + 4) of values (false at or past n) as a mask: four
// whole lanes widened at once (a bool is one byte, 0 or 1), not a lane at a
// time with a test of n each. The four bytes are read as one word and each
// lane shifts its own byte down (x86-64 is little-endian: byte l is bits
// 8l to 8l + 7) (GCC's __builtin_convertvector of the bytes
// went through general registers a byte at a time: most of
// clearance_stretches' time, perf, session 53).
inline Mask4 lanes_of(const bool* values, int first, int n) {
    if (first + 4 <= n) {
        typedef unsigned long long Word4 __attribute__((vector_size(32)));
        uint32_t word;
        std::memcpy(&word, values + first, sizeof word);
        const Word4 bits = ((Word4{} + word) >> Word4{0, 8, 16, 24}) & 1;
        return -(Mask4)bits;
    }
    Mask4 v{};
    for (int l = 0; first + l < n; ++l) v[l] = -static_cast<long long>(values[first + l]);
    return v;
}

// Lanes [first, first + 4) of v into out, those before n.
inline void store_lanes(Double4 v, int first, int n, double* out) {
    if (first + 4 <= n) std::memcpy(out + first, &v, sizeof v);
    else
        for (int l = 0; first + l < n; ++l) out[first + l] = v[l];
}

// Lanes [first, first + 4) of mask m (each lane all ones or none) into out
// as bools, those before n.
inline void store_lanes(Mask4 m, int first, int n, bool* out) {
    if (first + 4 <= n) {
        // Each lane's low byte (its first, little-endian) picked out by a shuffle (the conversion,
        // as above, went byte by byte).
        typedef signed char Char32 __attribute__((vector_size(32)));
        const Mask4 ones = m & 1;
        const Char32 chars = (Char32)ones;
        const Byte4 bytes = __builtin_shufflevector(chars, chars, 0, 8, 16, 24);
        std::memcpy(out + first, &bytes, sizeof bytes);
        return;
    }
    for (int l = 0; first + l < n; ++l) out[first + l] = m[l] != 0;
}

}  // namespace lc
