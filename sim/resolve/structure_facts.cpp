#include "sim/resolve/structure_facts.h"

#include "traces/accel/accel.h"
#include "traces/accel/accel_io.h"
#include "traces/accel/leaf_blocks.h"
#include "traces/common/error.h"
#include "traces/format/trace_reader.h"

namespace rtsim {

using nlohmann::json;

std::string StructureFacts::name() const {
    return (source.empty() ? "structure '" : "this trace's structure '") + kind +
           (blas_kind.empty() ? "'" : "' (BLASes: " + blas_kind + ")");
}

json StructureFacts::to_json() const {
    return {{"kind", kind},
            {"blas_kind", blas_kind.empty() ? json(nullptr) : json(blas_kind)},
            {"capabilities", caps.to_json()},
            {"stack_entry_bytes", stack_entry_bytes},
            {"compressed_leaves", compressed_leaves},
            {"frames", frames},
            {"shading_sections", shading_sections}};
}

StructureFacts structure_facts(const std::string& kind, const std::string& blas_kind, bool compressed_leaves) {
    StructureFacts f;
    f.kind = kind;
    f.blas_kind = kind == "two_level" ? (blas_kind.empty() ? "bvh2" : blas_kind) : "";
    f.caps = accel_capabilities(kind, f.blas_kind);
    f.stack_entry_bytes = f.caps.stack_entry_bytes;
    f.compressed_leaves = compressed_leaves;
    return f;
}

StructureFacts structure_facts(TraceReader& reader) {
    const std::string& path = reader.path();
    const json d = read_accel_descriptor(reader);
    const std::string where = path + ": section ACCL";
    require(d.is_object() && d.contains("kind") && d["kind"].is_string(), where + ": the descriptor has no 'kind'");
    const json params = d.value("params", json::object());
    const std::string blas = params.is_object() && params.contains("blas_kind") && params["blas_kind"].is_string()
                                 ? params["blas_kind"].get<std::string>()
                                 : "";
    bool compressed = false;
    for (const json& r : d.value("regions", json::array()))
        if (r.is_object() && (r.value("name", "") == kLeafBlocksRegion ||
                              r.value("name", "") == std::string("blas_") + kLeafBlocksRegion))
            compressed = true;
    StructureFacts f;
    try {
        f = structure_facts(d["kind"].get<std::string>(), blas, compressed);
    } catch (const Error& e) {
        throw Error(where + ": " + e.what());
    }
    f.source = path;
    // Traces written before structures recorded their stack entry: a BVH's 8 bytes.
    const json stats = d.value("stats", json::object());
    const json bytes = stats.is_object() ? stats.value("stack_entry_bytes", json(kBvhStackEntryBytes))
                                         : json(kBvhStackEntryBytes);
    require(bytes.is_number_unsigned() && bytes.get<uint64_t>() >= 1 && bytes.get<uint64_t>() <= 64,
            where + ": stats 'stack_entry_bytes' must be an integer in 1..64, got " + bytes.dump());
    f.stack_entry_bytes = bytes.get<uint32_t>();
    const json order = stats.is_object() ? stats.value("anyhit_order", json("nearest")) : json("nearest");
    require(order.is_string() && parse_anyhit_order(order.get<std::string>(), &f.traced_anyhit_order),
            where + ": stats 'anyhit_order' must be one of nearest, largest_box, fixed, got " + order.dump());
    if (reader.has(SectionKind::frames)) f.frames = reader.section(SectionKind::frames).record_count;
    f.shading_sections = reader.has(SectionKind::shading) && reader.has(SectionKind::tri_shading) &&
                         reader.has(SectionKind::materials);
    return f;
}

}  // namespace rtsim
