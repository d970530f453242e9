// libFuzzer target: the glTF loader (load_gltf) on arbitrary bytes, as a .gltf or a .glb
// (chosen by the GLB magic, like the loader). Contract: rtsim::Error or a Scene, never a crash,
// a hang or a sanitizer report. A loaded scene small enough is also built into a BVH.
//
// Structured mode, for inputs that start with "RTSIMNUM": u32 n, n bytes of a glTF JSON document
// (the seeds carry one with a camera, a material, instancing and node transforms), then edits of
// 10 bytes each: u16 which number or container of the document (in document order, modulo their
// count), u8 what to put there, u8 unused, 6 bytes of payload. Byte-level mutations rarely keep
// JSON valid; these keep it valid and change one value's number or type at a time (3 -> 3.0,
// 3.5, -2, 1e20, "3", null, [], {}), the class of input the loader must read by value.
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "traces/bvh/builder.h"
#include "traces/common/error.h"
#include "traces/scene/gltf_loader.h"

namespace {

using nlohmann::json;

/// Every number, array and object of the document, depth first.
void collect(json& j, std::vector<json*>& out) {
    if (j.is_number() || j.is_array() || j.is_object()) out.push_back(&j);
    if (j.is_array() || j.is_object())
        for (auto& child : j) collect(child, out);
}

json replacement(const json& old, uint8_t kind, const uint8_t* p) {
    int64_t i = 0;
    std::memcpy(&i, p, 6);
    i = (i << 16) >> 16;  // sign-extend 48 bits
    const double d = old.is_number() ? old.get<double>() : double(i);
    switch (kind % 12) {
        case 0: return double(d);                   // 3 -> 3.0
        case 1: return d + 0.5;                     // fractional
        case 2: return -d - 1;                      // negative
        case 3: return std::ldexp(1.0, int(i % 80));  // up to 2^79
        case 4: return i;                           // an arbitrary integer
        case 5: return std::to_string(i);           // a string
        case 6: return nullptr;
        case 7: return bool(i & 1);
        case 8: return json::array({d, d, d});
        case 9: return json::object({{"index", i}});
        case 10: return std::nan("");               // dumped as null by nlohmann
        default: return d * 1e-30;                  // a vanishing scale
    }
}

std::string structured(const uint8_t* data, size_t size) {
    if (size < 12) return {};
    uint32_t n = 0;
    std::memcpy(&n, data + 8, 4);
    if (n > size - 12) return {};
    json doc = json::parse(data + 12, data + 12 + n, nullptr, false);
    if (doc.is_discarded()) return {};
    for (const uint8_t* p = data + 12 + n; p + 10 <= data + size; p += 10) {
        std::vector<json*> values;
        collect(doc, values);
        if (values.empty()) break;
        uint16_t which = 0;
        std::memcpy(&which, p, 2);
        json& target = *values[which % values.size()];
        target = replacement(target, p[2], p + 4);
    }
    return doc.dump();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    // One scratch file per process; relative buffer URIs resolve beside it.
    static const std::string path = "/tmp/rtsim_fuzz_gltf_" + std::to_string(::getpid()) + ".gltf";
    std::string text(reinterpret_cast<const char*>(data), size);
    if (size >= 8 && std::memcmp(data, "RTSIMNUM", 8) == 0) text = structured(data, size);
    std::ofstream(path, std::ios::binary | std::ios::trunc).write(text.data(), std::streamsize(text.size()));
    try {
        rtsim::Scene scene = rtsim::load_gltf(path);
        if (scene.triangle_count() <= 4096) rtsim::build_bvh(scene);
    } catch (const rtsim::Error&) {
    }
    return 0;
}
