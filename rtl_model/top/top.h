#pragma once
// The accelerator: dispatch -> N traversal units (each with a private L1 and, unless shared,
// private box/triangle/any-hit pipelines) -> shared banked L2 -> DRAM channels. Built from the
// config; blocks the workload does not call for are not instantiated, and instantiated()
// says what was built and why (DESIGN rule 10).
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
#include "rtl_model/top/memory_image.h"
#include "rtl_model/traversal/traversal_unit.h"

namespace rtsim {

/// What the workload calls for, read from the trace by the harness.
struct WorkloadFeatures {
    bool anyhit_triangles = false;  ///< the BVH has alpha-MASK triangles
    uint64_t occlusion_rays = 0;    ///< any-hit (shadow) rays in the trace
    bool instancing = false;        ///< two-level BVH (not produced by the tracer yet)
};

class IdealMemory;

class Top : public sc_core::sc_module {
public:
    Top(sc_core::sc_module_name name, const SimConfig& config, const MemoryImage& image, RayStream& rays,
        RaySinkIf& sink, const WorkloadFeatures& features);
    ~Top() override;

    /// Cycle the last ray finished.
    Cycle total_cycles() const;
    /// Stats of every block, keyed by SystemC instance name.
    nlohmann::json stats_json() const;
    /// [{block, instantiated, why}]
    const nlohmann::json& instantiated() const { return m_instantiated; }
    const Dram* dram() const { return m_dram.get(); }
    uint32_t units() const { return uint32_t(m_units.size()); }

private:
    std::unique_ptr<Pipeline> make_pipeline(const std::string& name, const PipelineConfig& c);
    void build_memory();
    void build_pipelines(const WorkloadFeatures& features);
    void build_ray_buffer(const MemoryImage& image);

    const SimConfig& m_config;
    std::unique_ptr<Dispatch> m_dispatch;
    std::unique_ptr<Dram> m_dram;
    std::unique_ptr<Cache> m_l2;
    std::unique_ptr<IdealMemory> m_ideal;
    std::vector<std::unique_ptr<Cache>> m_l1;
    std::vector<std::unique_ptr<Pipeline>> m_box, m_tri, m_anyhit;
    std::vector<std::unique_ptr<TraversalUnit>> m_units;
    TreeletPartition m_partition;
    std::unique_ptr<RayBuffer> m_ray_buffer;
    nlohmann::json m_instantiated = nlohmann::json::array();
};

}  // namespace rtsim
