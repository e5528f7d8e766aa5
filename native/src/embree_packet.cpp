#include "embree_packet.h"

#include <cstdlib>
#include <cstring>
#include <string>

namespace lc {

const char* embree_device_config() {
    // Read once: every Scene of the process then uses the same kernels.
    static const std::string config = [] {
        const char* isa = std::getenv("LENSCOMPARE_EMBREE_ISA");
        return (isa && *isa) ? std::string("max_isa=") + isa : std::string();
    }();
    return config.empty() ? nullptr : config.c_str();
}

RTCSceneFlags embree_edge_flags() {
    // Read per scene (not once): bench_peers.py times both settings in one process.
    const char* robust = std::getenv("LENSCOMPARE_EMBREE_ROBUST");
    return (robust && std::strcmp(robust, "0") == 0) ? RTC_SCENE_FLAG_NONE : RTC_SCENE_FLAG_ROBUST;
}

}  // namespace lc
