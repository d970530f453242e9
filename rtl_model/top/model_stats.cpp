#include "rtl_model/top/model_stats.h"

#include <array>
#include <string>

#include "rtl_model/dispatch/dispatch.h"
#include "rtl_model/isect/pipeline.h"
#include "rtl_model/mem/mem_stats.h"
#include "rtl_model/ray_buffer/ray_buffer.h"
#include "rtl_model/shading/shading_block.h"
#include "rtl_model/traversal/traversal_unit.h"
#include "traces/common/error.h"

namespace rtsim {

const StatBlock& model_stats() {
    static const StatBlock block = [] {
        StatBlock b{"model",
                    {
                        {"dispatch", "", "dispatch's counters (`model.dispatch`)"},
                        {"units", "", "`{unit: stats}` per traversal unit `tu0`, `tu1`, ... (`model.units.<unit>`)"},
                        {"l1", "", "`{l1: stats}` per unit's L1 `l1_0`, ... (caches); absent with `ideal_memory`", false, true},
                        {"l2", "", "the shared L2 (caches); absent with `ideal_memory`", false, true},
                        {"dram", "", "DRAM (`model.dram`); absent with `ideal_memory`", false, true},
                        {"ideal_memory", "", "only with `ideal_memory`: the one memory that serves every access", false, true},
                        {"ray_buffer", "", "only with `treelets.enabled` (`model.ray_buffer`)", false, true},
                        {"treelet_prefetch", "", "only with `treelets.prefetch` and `treelets.enabled` false: `{treelets, prefetch}`, the partition and the footprint table the prefetchers use, as `model.ray_buffer` reports them with treelet queues", false, true},
                        {"cycle_accounting", "", "where ray-context time went (`model.cycle_accounting`); timed levels only", false, true},
                        {"utilization", "", "shared resources' busy fractions (`model.utilization`); timed levels only", false, true},
                        {"analytic", "", "the analytic level's closed form (`model.analytic`); analytic level only", false, true},
                        {"shading", "", "only with `shading.enabled`: the frame, shader cores, texture caches and sorting stage (`model.shading`)", false, true},
                        {"build_unit", "", "only for animated traces whose frames record their builds, with `build_unit.enabled`: the frames' builds and refits (`model.build_unit`)", false, true},
                    }};
        for (const char* kind : kOpKindNames)
            b.stats.push_back({kind, "", "`{pipe: stats}`: the pipeline blocks of this operation kind, when built (`model.<kind>.<pipe>`)", false, true});
        return b;
    }();
    return block;
}

const StatBlock& cycle_accounting_stats() {
    static const StatBlock block{
        "model.cycle_accounting",
        {
            {"context_cycles", "context-cycles", "units x contexts x cycles"},
            {"by_use", "context-cycles", "`{use: cycles}` summed over units (the per-unit figures are `model.units.<unit>.cycle_accounting`)"},
            {"fractions", "fraction", "`{use: by_use / context_cycles}`"},
        }};
    return block;
}

namespace {

/// "pipe_box", "pipe_triangle", ...: the utilisation key of each operation kind's pipelines.
const std::array<std::string, kOpKindCount>& pipe_keys() {
    static const std::array<std::string, kOpKindCount> keys = [] {
        std::array<std::string, kOpKindCount> k;
        for (int i = 0; i < kOpKindCount; ++i) k[size_t(i)] = std::string("pipe_") + kOpKindNames[size_t(i)];
        return k;
    }();
    return keys;
}

}  // namespace

const StatBlock& utilization_stats() {
    static const StatBlock block = [] {
        StatBlock b{"model.utilization",
                    {
                        {"dram_bandwidth", "fraction", "bytes moved / peak; absent with `ideal_memory`", false, true},
                        {"l1_banks", "fraction", "L1 accesses x `bank_cycles` / bank-cycles; absent with `ideal_memory`", false, true},
                        {"l2_banks", "fraction", "the L2's the same way; absent with `ideal_memory`", false, true},
                        {"l1_mshrs", "fraction", "L1 MSHRs held / MSHRs; absent with `ideal_memory`", false, true},
                        {"l2_mshrs", "fraction", "L2 MSHRs held / MSHRs; absent with `ideal_memory`", false, true},
                    }};
        for (const std::string& key : pipe_keys())
            b.stats.push_back({key.c_str(), "fraction", "issue slots used / slots of this kind's pipelines, when built", false, true});
        return b;
    }();
    return block;
}

namespace {

/// Checks each value of a group ({"tu0": {...}, ...}) against `block`.
void check_group(const nlohmann::json& group, const StatBlock& block) {
    require(group.is_object(), std::string("stats: '") + block.path + "' group is not an object");
    for (const auto& item : group) block.check(item);
}

}  // namespace

std::string traversal_units_text(const TraversalConfig& t) {
    return std::to_string(t.units) + " units x " + std::to_string(t.contexts()) + " ray contexts";
}

void check_model_stats(const nlohmann::json& m, const std::string& unit_kind) {
    model_stats().check(m);
    dispatch_stats().check(m.at("dispatch"));
    check_group(m.at("units"), unit_stats_of(unit_kind));
    for (const char* kind : kOpKindNames)
        if (m.contains(kind)) check_group(m.at(kind), pipeline_stats());
    if (m.contains("l1")) check_group(m.at("l1"), cache_stats());
    if (m.contains("l2")) cache_stats().check(m.at("l2"));
    if (m.contains("dram")) dram_stats().check(m.at("dram"));
    if (m.contains("ideal_memory")) ideal_memory_stats().check(m.at("ideal_memory"));
    if (m.contains("ray_buffer")) ray_buffer_stats().check(m.at("ray_buffer"));
    if (m.contains("cycle_accounting")) cycle_accounting_stats().check(m.at("cycle_accounting"));
    if (m.contains("utilization")) utilization_stats().check(m.at("utilization"));
    if (m.contains("shading")) shading_stats().check(m.at("shading"));
}

RTSIM_REGISTER_STAT_BLOCK(model_stats)
RTSIM_REGISTER_STAT_BLOCK(cycle_accounting_stats)
RTSIM_REGISTER_STAT_BLOCK(utilization_stats)

}  // namespace rtsim
