// Code per instruction set, picked for this CPU: a family of SIMD kernels
// (lens trace, own primitives and shading, random numbers) lists its kernels
// slowest first and says which this CPU runs, and single functions are built
// per set by the compiler (LC_BUILT_PER_ISA). Every choice gives the same bits.
#pragma once

#include <cstddef>

// A function GCC builds once per instruction set, the library picking one
// for this CPU when it loads (target_clones): for loops over a packet's
// lanes that are not a kernel family of their own. No FMA contraction and
// IEEE operations only, so every build gives the same bits.
#define LC_BUILT_PER_ISA __attribute__((target_clones("default", "avx2", "avx512f")))

namespace lc {

// The last of kernels (slowest first) that available says this CPU runs;
// the first when none is (the portable one always runs).
template <class Kernel, size_t N>
Kernel fastest_available(const Kernel (&kernels)[N], bool (*available)(Kernel)) {
    Kernel best = kernels[0];
    for (Kernel candidate : kernels)
        if (available(candidate)) best = candidate;
    return best;
}

}  // namespace lc
