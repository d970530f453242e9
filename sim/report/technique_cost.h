#pragma once
// What each technique adds to the chip, priced by the first-order model (docs/energy_area.md,
// "What each technique adds"): the compressed nodes' dequantisers, the compressed leaves'
// decoders, the execution model's control (a SIMT unit's warp scheduler, lane masks and
// coalescer; a packet unit's masks; a MIMD unit's per-context scheduler), the ray-sorting stage,
// the treelet prefetcher's stream state and request queue, and the mailboxes' comparators. Each
// block is SRAM bytes (priced by the SRAM rule) and logic (adders and comparators priced by
// Horowitz's figures, state kept in flip-flops priced as `kFlopCellFactor` SRAM cells), and an
// energy per event the run counts. A technique that is off adds nothing.
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "sim/config/config.h"
#include "traces/common/work_counts.h"

namespace rtsim {

/// The blocks a technique adds, for the area model.
struct TechniqueArea {
    std::map<std::string, double> sram_bytes;  ///< block -> SRAM data bytes
    std::map<std::string, double> logic_mm2;   ///< block -> logic and flip-flop area, mm^2 at the node
};

/// The structure's blocks the area model prices, as entries of stats.json "instantiated":
/// `node_decoder` (compressed nodes: cwbvh kinds, or two levels over them) and `leaf_decoder`
/// (compressed leaves). The run loop adds them to every level's list.
nlohmann::json structure_blocks(const std::string& kind, const std::string& blas_kind, bool compressed_leaves);

/// Every technique's added area for this config and these instantiated blocks.
TechniqueArea technique_area(const SimConfig& config, const nlohmann::json& instantiated);

/// Every technique's dynamic energy over the run, pJ by block (the blocks technique_area
/// prices), from the work totals and the model's stats (warp steps, prefetched lines).
std::map<std::string, double> technique_energy_pj(const SimConfig& config, const WorkTotals& work,
                                                  const nlohmann::json& stats);

}  // namespace rtsim
