#include "rtl_model/common/treelet_map.h"

#include <algorithm>

namespace rtsim {

nlohmann::json TreeletMap::partition_json() const {
    const auto& t = m_partition.treelets;
    uint64_t max_bytes = 0, sum_bytes = 0;
    uint32_t max_depth = 0;
    for (const TreeletInfo& i : t) {
        max_bytes = std::max(max_bytes, i.bytes);
        sum_bytes += i.bytes;
        max_depth = std::max(max_depth, i.depth);
    }
    return {{"count", t.size()},
            {"budget_bytes", m_partition.budget_bytes},
            {"mean_bytes", t.empty() ? 0.0 : double(sum_bytes) / double(t.size())},
            {"max_bytes", max_bytes},
            {"max_depth", max_depth}};
}

nlohmann::json TreeletMap::prefetch_json() const {
    const uint64_t learnt = m_footprints->treelets_learnt(), lines = m_footprints->lines_learnt();
    return {{"treelets_learnt", learnt}, {"lines_learnt", lines},
            {"mean_lines", learnt ? double(lines) / double(learnt) : 0.0}};
}

}  // namespace rtsim
