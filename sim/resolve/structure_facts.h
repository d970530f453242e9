#pragma once
// What a run knows of its acceleration structure before it builds anything: read from a trace's
// ACCL descriptor (kind, BLAS kind, stack entry, compressed leaves, frames), or made from a kind
// name alone, so sweeps and Python check a spec before any trace exists.
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "traces/accel/capabilities.h"
#include "traces/accel/step_options.h"

namespace rtsim {

class TraceReader;

struct StructureFacts {
    std::string kind = "bvh2";  ///< the image's kind ("two_level" for two levels)
    std::string blas_kind;      ///< two levels: the BLASes' kind
    AccelCapabilities caps;     ///< what the kind offers (its registry entry's, capabilities.h)
    uint32_t stack_entry_bytes = 8;  ///< what one stack entry holds (the trace's record, else the kind's)
    bool compressed_leaves = false;  ///< its triangles are compressed leaf blocks
    uint64_t frames = 1;             ///< frames of an animated trace
    bool shading_sections = true;    ///< the trace carries shading sections (version 5; facts from a name: yes)
    /// The child order its any-hit rays were traced in (the structure's stats' anyhit_order,
    /// `rtsim trace --anyhit-order`; nearest first when absent).
    AnyHitOrder traced_anyhit_order = AnyHitOrder::nearest;
    std::string source;              ///< the trace (messages), or "" for facts from a name

    /// How messages name it: "this trace's structure 'kdtree'" or "structure 'kdtree'".
    std::string name() const;
    nlohmann::json to_json() const;
};

/// The facts of the trace `reader` reads (its descriptor only: no region is read). Throws
/// rtsim::Error naming the trace when the descriptor is unusable.
StructureFacts structure_facts(TraceReader& reader);
/// The facts of a structure by name, before it is built (`blas_kind` for kind "two_level").
StructureFacts structure_facts(const std::string& kind, const std::string& blas_kind = "",
                               bool compressed_leaves = false);

}  // namespace rtsim
