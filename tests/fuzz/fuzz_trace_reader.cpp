// libFuzzer target: the trace reader and the BVH image validation. The first byte picks a mode:
//   even: the rest is a trace file: open, verify every CRC, read every section;
//   odd:  the rest is a raw image (u16 node count, nodes, u16 triangle count, triangles, then
//         rays), so mutations reach the validator without breaking CRCs first.
// Either way an image that the structure's validation accepts (load_accel for a trace, whatever
// its kind; validate_bvh2 for a raw binary BVH) is traversed with up to 16 of the rays (the
// fused loop and the stepper, both modes): the validation's contract is that this never crashes.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "traces/accel/accel.h"
#include "traces/accel/accel_io.h"
#include "traces/accel/bvh2/bvh2.h"
#include "traces/common/error.h"
#include "traces/format/trace_reader.h"

namespace {

using namespace rtsim;

/// Drives one ray through a stepper to the end, as the model does.
void step_through(const Accel& accel, const Ray& ray, TraversalMode mode) {
    std::unique_ptr<Stepper> s = accel.make_stepper();
    s->begin(ray, mode);
    while (!s->done()) {
        s->plan();
        s->execute();
    }
}

void traverse(const Accel& accel, const std::vector<RayRecord>& rays) {
    for (size_t i = 0; i < rays.size() && i < 16; ++i) {
        const Ray ray = ray_from_record(rays[i]);
        for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
            accel.trace(ray, mode);
            step_through(accel, ray, mode);
        }
    }
}

void traverse_raw(const std::vector<HwNode>& nodes, const std::vector<HwTriangle>& tris,
                  const std::vector<RayRecord>& rays) {
    HwBvh bvh;
    bvh.nodes = nodes;
    bvh.triangles = tris;
    validate_bvh2(bvh2_view(bvh), "fuzz");  // throws on a bad image: then nothing is traversed
    for (size_t i = 0; i < rays.size() && i < 16; ++i) {
        const Ray ray = ray_from_record(rays[i]);
        for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
            trace_ray(bvh, ray, mode);
            trace_ray_stepper(bvh, ray, mode);
        }
    }
}

template <class T>
std::vector<T> take(const uint8_t*& p, const uint8_t* end, size_t count) {
    count = std::min(count, size_t(end - p) / sizeof(T));
    std::vector<T> out(count);
    if (count) std::memcpy(static_cast<void*>(out.data()), p, count * sizeof(T));
    p += count * sizeof(T);
    return out;
}

uint16_t u16(const uint8_t*& p, const uint8_t* end) {
    if (end - p < 2) return 0;
    uint16_t v = uint16_t(p[0] | p[1] << 8);
    p += 2;
    return v;
}

void raw_image(const uint8_t* p, const uint8_t* end) {
    std::vector<HwNode> nodes = take<HwNode>(p, end, u16(p, end));
    std::vector<HwTriangle> tris = take<HwTriangle>(p, end, u16(p, end));
    std::vector<RayRecord> rays = take<RayRecord>(p, end, 16);
    traverse_raw(nodes, tris, rays);
}

void trace_file(const uint8_t* data, size_t size) {
    static const std::string path = "/tmp/rtsim_fuzz_trace_" + std::to_string(::getpid()) + ".rtt";
    std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), std::streamsize(size));
    TraceReader reader(path);
    reader.verify_all();
    for (const SectionInfo& s : reader.sections())
        if (s.bytes <= (64u << 20)) {
            std::vector<uint8_t> buffer(size_t(s.bytes));
            reader.read(s.kind, 0, s.record_count, buffer.data());
        }
    if (!reader.has(SectionKind::accel)) return;
    const std::unique_ptr<Accel> accel = load_accel(read_accel_image(reader), "fuzz");
    std::vector<RayRecord> rays;
    if (reader.has(SectionKind::rays)) {
        const uint64_t n = std::min<uint64_t>(16, reader.section(SectionKind::rays).record_count);
        rays.resize(size_t(n));
        reader.read(SectionKind::rays, 0, n, rays.data());
    }
    traverse(*accel, rays);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size == 0) return 0;
    try {
        if (data[0] & 1) raw_image(data + 1, data + size);
        else trace_file(data + 1, size - 1);
    } catch (const rtsim::Error&) {
    }
    return 0;
}
