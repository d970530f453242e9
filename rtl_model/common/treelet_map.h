#pragma once
// The structure's treelet partition as the machine's blocks see it (docs/treelets.md): which
// treelet a step's locality key belongs to, for treelet scheduling (the ray buffer's queues) and
// treelet prefetching (the footprint table the units' prefetchers learn and read). Built by the
// top level when either is on; prefetching needs no ray buffer (Chou, Nowicki & Aamodt 2023
// prefetch on a warp-based RT unit without treelet queues).
#include <cstdint>
#include <memory>

#include <nlohmann/json.hpp>

#include "rtl_model/common/treelet_footprint.h"
#include "traces/accel/locality.h"
#include "traces/accel/step_plan.h"

namespace rtsim {

/// No treelet yet: a ray before its first step.
inline constexpr uint32_t kNoTreelet = ~0u;

class TreeletMap {
public:
    /// `footprints` null: no prefetching.
    TreeletMap(LocalityPartition partition, std::unique_ptr<TreeletFootprints> footprints)
        : m_partition(std::move(partition)), m_footprints(std::move(footprints)) {}

    const LocalityPartition& partition() const { return m_partition; }
    uint32_t treelets() const { return uint32_t(m_partition.treelets.size()); }
    /// Treelet of a step's locality key (never kNoLocality: such steps keep their ray's treelet).
    uint32_t treelet_of(uint32_t locality) const { return m_partition.group_of[locality]; }
    /// The treelet a ray's first step runs in (the root treelet when the step names none).
    uint32_t first_treelet(uint32_t locality) const {
        return locality == kNoLocality ? m_partition.root_group : m_partition.group_of[locality];
    }
    /// The prefetchers' footprint table, or null when prefetching is off.
    TreeletFootprints* footprints() const { return m_footprints.get(); }

    /// {count, budget_bytes, mean_bytes, max_bytes, max_depth} of the partition.
    nlohmann::json partition_json() const;
    /// {treelets_learnt, lines_learnt, mean_lines} of the footprint table (prefetching on).
    nlohmann::json prefetch_json() const;

private:
    LocalityPartition m_partition;
    std::unique_ptr<TreeletFootprints> m_footprints;
};

}  // namespace rtsim
