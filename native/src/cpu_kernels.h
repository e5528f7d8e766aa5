// Choosing among a family of SIMD kernels (lens trace, own primitives and
// shading, random numbers): each family lists its kernels slowest first and
// says which this CPU runs; every kernel of a family gives the same bits.
#pragma once

#include <cstddef>

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
