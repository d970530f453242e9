// libFuzzer target: the glTF loader (load_gltf) on arbitrary bytes, as a .gltf or a .glb
// (chosen by the GLB magic, like the loader). Contract: rtsim::Error or a Scene, never a crash,
// a hang or a sanitizer report. A loaded scene small enough is also built into a BVH.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <string>

#include "traces/bvh/builder.h"
#include "traces/common/error.h"
#include "traces/scene/gltf_loader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    // One scratch file per process; relative buffer URIs resolve beside it.
    static const std::string path = "/tmp/rtsim_fuzz_gltf_" + std::to_string(::getpid()) + ".gltf";
    std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), std::streamsize(size));
    try {
        rtsim::Scene scene = rtsim::load_gltf(path);
        if (scene.triangle_count() <= 4096) rtsim::build_bvh(scene);
    } catch (const rtsim::Error&) {
    }
    return 0;
}
