// Which batch lens-trace kernel this CPU runs. All give the same bits.
#include "cpu_kernels.h"
#include "lens/lens_trace.h"

namespace lc {

bool lens_trace_kernel_available(LensTraceKernel kernel) {
    switch (kernel) {
        case LensTraceKernel::Portable: return true;
        // The single-precision kernel fuses multiply-adds (lens_trace_lanes.h)
        case LensTraceKernel::Avx2: return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
        case LensTraceKernel::Avx512:
            return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq");
    }
    return false;
}

LensTraceKernel best_lens_trace_kernel() {
    static const LensTraceKernel best = fastest_available(kLensTraceKernels, lens_trace_kernel_available);
    return best;
}

const char* lens_trace_kernel_name(LensTraceKernel kernel) {
    switch (kernel) {
        case LensTraceKernel::Portable: return "portable";
        case LensTraceKernel::Avx2: return "avx2";
        case LensTraceKernel::Avx512: return "avx512";
    }
    return "?";
}

}  // namespace lc
