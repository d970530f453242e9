#include "sim/harness/structure_defaults.h"

#include <string>

#include "sim/harness/run_files.h"
#include "traces/accel/accel_io.h"
#include "traces/common/error.h"
#include "traces/format/trace_reader.h"

namespace rtsim {

SimOptions with_structure_defaults(const SimOptions& options) {
    SimOptions o = options;
    if (o.config.traversal.stack_entry_bytes != 0) return o;
    TraceReader reader(trace_file(o.trace));
    const nlohmann::json d = read_accel_descriptor(reader);
    const nlohmann::json stats = d.is_object() ? d.value("stats", nlohmann::json::object()) : nlohmann::json::object();
    const nlohmann::json bytes = stats.is_object() ? stats.value("stack_entry_bytes", nlohmann::json(kBvhStackEntryBytes))
                                                   : nlohmann::json(kBvhStackEntryBytes);
    require(bytes.is_number_unsigned() && bytes.get<uint64_t>() >= 1 && bytes.get<uint64_t>() <= 64,
            reader.path() + ": section ACCL: stats 'stack_entry_bytes' must be an integer in 1..64, got " + bytes.dump());
    o.config.traversal.stack_entry_bytes = bytes.get<uint32_t>();
    return o;
}

void apply_short_stack(Accel& accel, const SimConfig& config) {
    const TraversalConfig& t = config.traversal;
    if (t.stack_overflow == StackOverflow::spill) return accel.set_short_stack(0);
    require(accel.supports_short_stack(),
            "config: 'traversal.stack_overflow' restart_trail needs a single-level BVH trace (bvh2, or a wide or "
            "compressed BVH); this trace's structure is '" + accel.kind() + "'; use traversal.stack_overflow spill");
    accel.set_short_stack(t.stack_entries);
}

void apply_box_precision(Accel& accel, const SimConfig& config) {
    const uint32_t bits = config.traversal.box_precision_bits;
    require(bits == 0 || accel.supports_reduced_precision_boxes(),
            "config: 'traversal.box_precision_bits' " + std::to_string(bits) +
                " needs a single-level BVH trace (bvh2, or a wide or compressed BVH); this trace's structure is '" +
                accel.kind() + "'; use traversal.box_precision_bits 0 (fp32)");
    accel.set_box_precision(bits);
}

}  // namespace rtsim
