#pragma once
// The accelerator: dispatch -> N traversal units (each with a private L1 and, unless shared,
// private pipelines for each operation kind the structure issues) -> shared banked L2 -> DRAM
// channels. Built from the config and the acceleration structure; blocks the workload does not
// call for are not instantiated, and instantiated() says what was built and why
// (docs/architecture.md, rule 10). Nothing here knows which structure it runs.
#include <array>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <systemc>

#include "rtl_model/dispatch/dispatch.h"
#include "rtl_model/isect/pipeline.h"
#include "rtl_model/mem/cache.h"
#include "rtl_model/mem/dram.h"
#include "rtl_model/ray_buffer/ray_buffer.h"
#include "rtl_model/shading/shading_block.h"
#include "rtl_model/traversal/traversal_unit.h"
#include "rtl_model/traversal/unit_kind.h"
#include "rtl_model/top/model_config.h"

namespace rtsim {

/// What the workload calls for, read from the trace by the harness.
struct WorkloadFeatures {
    uint64_t occlusion_rays = 0;    ///< any-hit (shadow) rays in the trace
};

class IdealMemory;

/// Running totals of the memory levels; per-frame figures are differences of two snapshots.
struct MemoryTotals {
    MemCounters l1;    ///< summed over the units' L1s
    MemCounters l2;
    MemCounters dram;
};

class Top : public sc_core::sc_module {
public:
    /// `config` is resolved (sim/resolve/resolve.h: ray contexts derived, the stack entry known);
    /// the steppers walk with `step` (the run's StepOptions).
    /// `shading`: the trace's shading tables when config.shading.enabled (the resolution step
    /// requires them then); the shading block sits between the units and `sink`.
    Top(sc_core::sc_module_name name, const ModelConfig& config, const Accel& accel, const StepOptions& step,
        const MemoryMap& map, RayStream& rays, RaySinkIf& sink, const WorkloadFeatures& features,
        const ShadingInputs* shading = nullptr);
    ~Top() override;

    /// Cycle the last ray finished.
    Cycle total_cycles() const;
    /// Stats of every block, keyed by SystemC instance name.
    nlohmann::json stats_json() const;
    /// [{block, instantiated, why}]
    const nlohmann::json& instantiated() const { return m_instantiated; }
    const Dram* dram() const { return m_dram.get(); }
    Dram* dram() { return m_dram.get(); }
    Dispatch& dispatch() { return *m_dispatch; }
    /// The shading block; null when the run does not model the frame.
    ShadingBlock* shading() { return m_shading.get(); }
    /// The frame's end: the last ray traced, or shaded when the frame is modelled.
    Cycle frame_cycles() const;
    /// The memory levels' counters so far (zeros with ideal_memory).
    MemoryTotals memory_totals() const;
    uint32_t units() const { return uint32_t(m_units.size()); }
    /// Functional warming with a read of [addr, addr + bytes) by unit `unit`: its L1, and the L2
    /// for the lines the L1 missed (Cache::warm; nothing with ideal_memory).
    void warm(uint32_t unit, uint64_t addr, uint32_t bytes);
    /// The memory level the units share (the L2, or ideal memory): where the build unit reads
    /// and writes (rtl_model/build_unit/build_unit.h).
    MemIf& shared_memory();

private:
    using PipelineSet = std::vector<std::unique_ptr<Pipeline>>;
    nlohmann::json cycle_accounting_json(Cycle total) const;
    nlohmann::json utilization_json(Cycle total) const;
    void build_memory();
    void build_pipelines(const Accel& accel);
    void build_treelets(const Accel& accel, const MemoryMap& map);
    void build_shading(const ShadingInputs* shading, RaySinkIf& sink);

    const ModelConfig& m_config;
    UnitContext m_unit_context;
    StepperPool m_steppers;
    std::unique_ptr<Dispatch> m_dispatch;
    std::unique_ptr<Dram> m_dram;
    std::unique_ptr<Cache> m_l2;
    std::unique_ptr<IdealMemory> m_ideal;
    std::vector<std::unique_ptr<Cache>> m_l1;
    std::array<PipelineSet, kOpKindCount> m_pipes;  ///< per operation kind: one per unit, or one pool
    std::vector<std::unique_ptr<TraversalUnit>> m_units;
    std::unique_ptr<TreeletMap> m_treelets;  ///< treelet scheduling or prefetching only
    std::unique_ptr<RayBuffer> m_ray_buffer;
    std::unique_ptr<ShadingBlock> m_shading;
    nlohmann::json m_instantiated = nlohmann::json::array();
};

}  // namespace rtsim
