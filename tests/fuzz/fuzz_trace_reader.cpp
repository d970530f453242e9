// libFuzzer target: the trace reader and the BVH image validation. The first byte picks a mode:
//   0 mod 4: the rest is a trace file: open, verify every CRC, read every section;
//   2 mod 4: the same, after every CRC (chunks, section table, header) is recomputed, so
//            mutations of a section's content reach the record checks (counts, frames) and
//            the structure's validation instead of stopping at a checksum;
//   odd:     the rest is a raw image (u16 node count, nodes, u16 triangle count, triangles, then
//            rays), so mutations reach the validator without breaking CRCs first.
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
#include "traces/format/trace_checks.h"
#include "traces/format/trace_layout.h"
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

/// Recomputes every CRC a trace holds where the bytes allow (what trace_forge.py does in tests):
/// chunk CRCs of each in-bounds section, the section table's and the header's.
void repair_crcs(std::vector<uint8_t>& f) {
    namespace tl = trace_layout;
    if (f.size() < tl::kHeaderBytes) return;
    tl::FileHeader h = tl::decode_header(f.data());
    if (h.section_count > 64 || h.table_offset > f.size() ||
        tl::table_bytes_for(h.section_count) > f.size() - h.table_offset)
        return;
    for (uint32_t i = 0; i < h.section_count; ++i) {
        const SectionInfo s = tl::decode_entry(&f[h.table_offset + size_t(i) * tl::kEntryBytes]);
        const uint64_t chunks = tl::chunk_count(s.bytes, s.chunk_bytes);
        if (s.offset > f.size() || s.bytes > f.size() - s.offset || s.crc_offset > f.size() ||
            chunks > (f.size() - s.crc_offset) / 4)
            continue;
        for (uint64_t c = 0; c < chunks; ++c) {
            const uint64_t b = c * s.chunk_bytes, n = std::min<uint64_t>(s.chunk_bytes, s.bytes - b);
            const uint32_t crc = tl::crc32_bytes(&f[s.offset + b], size_t(n));
            std::memcpy(&f[s.crc_offset + 4 * c], &crc, 4);
        }
    }
    const size_t n = size_t(h.section_count) * tl::kEntryBytes;
    const uint32_t crc = tl::crc32_bytes(&f[h.table_offset], n);
    std::memcpy(&f[h.table_offset + n], &crc, 4);
    uint8_t head[tl::kHeaderBytes];
    tl::encode_header(h, head);  // the same fields, the magic and a fresh header CRC
    std::memcpy(f.data(), head, tl::kHeaderBytes);
}

void trace_file(const uint8_t* data, size_t size, bool repair) {
    static const std::string path = "/tmp/rtsim_fuzz_trace_" + std::to_string(::getpid()) + ".rtt";
    std::vector<uint8_t> bytes(data, data + size);
    if (repair) repair_crcs(bytes);
    std::ofstream(path, std::ios::binary | std::ios::trunc)
        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    TraceReader reader(path);
    reader.verify_all();
    check_ray_sections(reader);  // as rtsim-sim and open_trace check the records
    for (const SectionInfo& s : reader.sections())
        if (s.bytes <= (64u << 20)) {
            std::vector<uint8_t> buffer(size_t(s.bytes));
            reader.read(s.kind, 0, s.record_count, buffer.data());
        }
    if (!reader.has(SectionKind::accel)) return;
    const std::unique_ptr<Accel> accel = load_accel(read_accel_image(reader), "fuzz");
    read_frame_table(reader, accel->frame_count());
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
        else trace_file(data + 1, size - 1, (data[0] & 2) != 0);
    } catch (const rtsim::Error&) {
    }
    return 0;
}
