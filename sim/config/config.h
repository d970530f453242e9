#pragma once
// The one config tree of the simulator (docs/architecture.md, rule 5): plain structs with
// defaults and units. Each block owns its config struct next to its code (rtl_model/<block>/
// *_config.h); this tree only composes them. Each struct lists its fields once in visit() with
// name, unit, range and a one-line doc; the JSON reader, writer, schema dump (for the Python
// dataclasses) and validate() are all visitors, so a field cannot be documented, defaulted or
// range-checked in one place and not another. Choices are enums, parsed once.
#include <cstdint>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>

#include "rtl_model/common/choice.h"
#include "rtl_model/dispatch/dispatch_config.h"
#include "rtl_model/isect/pipeline_config.h"
#include "rtl_model/mem/cache_config.h"
#include "rtl_model/mem/dram_config.h"
#include "rtl_model/ray_buffer/ray_buffer_config.h"
#include "rtl_model/traversal/mailbox_config.h"
#include "rtl_model/traversal/traversal_config.h"
#include "sim/harness/analytic_config.h"
#include "sim/harness/energy_config.h"
#include "sim/harness/sampling_config.h"
#include "traces/accel/step_plan.h"

namespace rtsim {

enum class Fidelity : uint8_t { functional = 0, analytic = 1, approx = 2, detailed = 3 };
inline constexpr Choices<Fidelity, 4> kFidelityChoices{{"functional", "analytic", "approx", "detailed"}};

struct SimConfig {
    double clock_ghz = 1.0;          ///< converts cycles to seconds
    Fidelity fidelity = Fidelity::approx;  ///< functional | analytic | approx | detailed (docs/fidelity.md)
    uint32_t quantum_cycles = 256;   ///< how far a unit may run ahead of SystemC time
    uint32_t interconnect_latency = 8;  ///< L1 to L2 one-way cycles
    bool ideal_memory = false;       ///< every access hits in L1 (upper bound on performance)
    DispatchConfig dispatch;
    TraversalConfig traversal;
    PipelineConfig box{8, 1, 2, Sharing::per_unit, 4};
    PipelineConfig triangle{20, 1, 1, Sharing::per_unit, 4};
    PipelineConfig anyhit{10, 1, 1, Sharing::per_unit, 4};
    PipelineConfig cell{4, 1, 1, Sharing::per_unit, 4};
    /// Instance transforms of two-level structures: a 3x4 matrix times the ray's origin and
    /// direction (18 multiply-adds), pipelined like a box test (Vulkan-Sim's instance transform).
    PipelineConfig transform{8, 1, 1, Sharing::per_unit, 4};
    /// Ray/split-plane tests of kd-trees, BIHs and octrees: (plane - origin) x 1/d and two
    /// compares, one slab of a box test; two per issue (a BIH node's pair).
    PipelineConfig plane{4, 1, 2, Sharing::per_unit, 4};
    MailboxConfig mailbox;
    // MSHRs: one per ray context in each L1, and enough in the L2 for the L1s' misses in flight
    // (docs/presets.md, "How the defaults were chosen": at 8 and 32 the MSHRs starved Sponza).
    CacheConfig l1{16, 4, 64, 4, 16, 1, 1};
    CacheConfig l2{1024, 16, 64, 20, 64, 8, 1};
    DramConfig dram;
    TreeletConfig treelets;
    SamplingConfig sampling;
    EnergyConfig energy;  ///< the energy and area model's technology (sim/harness/energy_area.h)
    AnalyticConfig analytic;  ///< the analytic level (sim/harness/analytic_config.h)

    /// The pipeline operations of `kind` go to. Adding an operation kind adds a PipelineConfig
    /// member, its visit() line and a case here (docs/accel.md, "Adding a structure").
    const PipelineConfig& pipeline(OpKind kind) const;
    PipelineConfig& pipeline(OpKind kind) { return const_cast<PipelineConfig&>(std::as_const(*this).pipeline(kind)); }

    template <class V>
    void visit(V& v) {
        v.field("clock_ghz", clock_ghz, "GHz", "Core clock: converts cycles to seconds", 0.001, 100.0);
        v.choice("fidelity", fidelity, kFidelityChoices, "Simulation level: functional (counts only), analytic (cache simulation + roofline), approx (timed SystemC model) or detailed (per-cycle arbitration, L2 MSHRs)");
        v.field("quantum_cycles", quantum_cycles, "cycles", "How far a traversal unit may run ahead of the others (temporal decoupling)", 1, 1u << 20);
        v.field("interconnect_latency", interconnect_latency, "cycles", "One-way latency between an L1 and the L2", 0, 10000);
        v.flag("ideal_memory", ideal_memory, "Every access hits in L1 at L1 latency: the upper bound on performance");
        v.section("dispatch", dispatch);
        v.section("traversal", traversal);
        v.section("box", box);
        v.section("triangle", triangle);
        v.section("anyhit", anyhit);
        v.section("cell", cell);
        v.section("transform", transform);
        v.section("plane", plane);
        v.section("mailbox", mailbox);
        v.section("l1", l1);
        v.section("l2", l2);
        v.section("dram", dram);
        v.section("treelets", treelets);
        v.section("sampling", sampling);
        v.section("energy", energy);
        v.section("analytic", analytic);
    }
};

/// Reads a config from JSON over the defaults; unknown keys and bad values throw rtsim::Error
/// naming the key path (e.g. "l1.size_kib").
SimConfig config_from_json(const nlohmann::json& j, const SimConfig& base = {});
/// Applies "key.path=value" (value parsed by the field's type).
void config_set(SimConfig& config, const std::string& assignment);
nlohmann::json config_to_json(const SimConfig& config);
/// Every field with default, unit, range, choices and doc: the schema the Python side mirrors.
nlohmann::json config_schema();
/// Range checks plus cross-field rules; throws rtsim::Error naming the field.
void validate(const SimConfig& config);

}  // namespace rtsim
