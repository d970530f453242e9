#pragma once
// The accelerator model's configuration: the blocks' configs (each declared next to its block,
// rtl_model/<block>/*_config.h) and the level flags that change how the model times (fidelity,
// ideal memory). The model owns it; the harness composes it with its own sections (sampling,
// energy, the analytic level: sim/config/config.h) into the one config tree. Each struct lists
// its fields once in visit() with name, unit, range and a one-line doc.
#include <cstdint>
#include <utility>
#include <vector>

#include "rtl_model/build_unit/build_unit_config.h"
#include "rtl_model/common/choice.h"
#include "rtl_model/dispatch/dispatch_config.h"
#include "rtl_model/isect/pipeline_config.h"
#include "rtl_model/mem/cache_config.h"
#include "rtl_model/mem/dram_config.h"
#include "rtl_model/ray_buffer/ray_buffer_config.h"
#include "rtl_model/shading/shading_config.h"
#include "rtl_model/traversal/mailbox_config.h"
#include "rtl_model/traversal/step_demand.h"
#include "rtl_model/traversal/traversal_config.h"
#include "traces/accel/step_plan.h"

namespace rtsim {

/// A pipeline with PipelineConfig's defaults (initiation interval 1, private to each unit, a pool
/// of 4 when shared) but its latency and width.
inline PipelineConfig pipeline_of(uint32_t latency, uint32_t width) {
    PipelineConfig p;
    p.latency = latency;
    p.width = width;
    return p;
}

/// How a run is simulated (docs/fidelity.md). The SystemC model runs approx and detailed; the
/// harness runs functional (reference traversal, no time) and analytic (a closed form).
enum class Fidelity : uint8_t { functional = 0, analytic = 1, approx = 2, detailed = 3 };
inline constexpr Choices<Fidelity, 4> kFidelityChoices{{"functional", "analytic", "approx", "detailed"}};

struct ModelConfig {
    double clock_ghz = 1.0;          ///< converts cycles to seconds
    Fidelity fidelity = Fidelity::approx;  ///< functional | analytic | approx | detailed (docs/fidelity.md)
    /// How far a unit may run ahead of SystemC time. 64: within a quantum the units' misses reach
    /// the shared L2 and DRAM out of time order, which at 256 made approx up to 5.5% slow on
    /// short traces and designs whose L2 MSHRs are busy, at the same wall time (docs/fidelity.md).
    uint32_t quantum_cycles = 64;
    uint32_t interconnect_latency = 8;  ///< L1 to L2 one-way cycles
    bool ideal_memory = false;       ///< every access hits in L1 (upper bound on performance)
    DispatchConfig dispatch;
    TraversalConfig traversal;
    // Each block's defaults are its config struct's; a member below names only what differs.
    /// Ray/box tests: both child boxes of a binary node in one issue.
    PipelineConfig box = pipeline_of(/*latency=*/8, /*width=*/2);
    /// Watertight ray/triangle tests (Woop et al. 2013): a longer pipeline, one test per issue.
    PipelineConfig triangle = pipeline_of(/*latency=*/20, /*width=*/1);
    /// Alpha tests of alpha-MASK triangles' texels.
    PipelineConfig anyhit = pipeline_of(/*latency=*/10, /*width=*/1);
    /// Grid cell steps (3D-DDA: a compare and an add per step).
    PipelineConfig cell = pipeline_of(/*latency=*/4, /*width=*/1);
    /// Instance transforms of two-level structures: a 3x4 matrix times the ray's origin and
    /// direction (18 multiply-adds), pipelined like a box test (Vulkan-Sim's instance transform).
    PipelineConfig transform = pipeline_of(/*latency=*/8, /*width=*/1);
    /// Ray/split-plane tests of kd-trees, BIHs and octrees: (plane - origin) x 1/d and two
    /// compares, one slab of a box test; two per issue (a BIH node's pair).
    PipelineConfig plane = pipeline_of(/*latency=*/4, /*width=*/2);
    /// Ray rotations of oriented nodes (obvh2): a 3x3 matrix from the unit's table times the
    /// ray's origin and direction (18 multiply-adds, no translation), one per oriented node
    /// ahead of its box tests. An assumption: no public figure prices RDNA 4's OBB transform.
    PipelineConfig obb = pipeline_of(/*latency=*/6, /*width=*/1);
    /// Ray/sphere tests (curved primitives; Haines et al. 2019): a square root and two divides
    /// after the dot products, as long a pipeline as the triangle's. An assumption: NVIDIA's
    /// Blackwell RT cores test spheres natively, but no public figure gives their latency.
    PipelineConfig sphere = pipeline_of(/*latency=*/20, /*width=*/1);
    /// Ray/capsule tests (curved primitives): a cylinder's and two spheres' crossings, three of
    /// the sphere's quadrics side by side, then their selection; a longer pipeline. An
    /// assumption, as the sphere's (Blackwell's linear swept spheres are unpriced in public).
    PipelineConfig capsule = pipeline_of(/*latency=*/28, /*width=*/1);
    MailboxConfig mailbox;
    // MSHRs: one per ray context in each L1, and enough in the L2 for the L1s' misses in flight
    // (docs/presets.md, "How the defaults were chosen": at 8 and 32 the MSHRs starved Sponza).
    CacheConfig l1 = [] {
        CacheConfig c;  // 16 KiB, 4 ways, 64-byte lines, 4 cycles, 1 bank
        c.mshrs = 16;
        return c;
    }();
    CacheConfig l2 = [] {
        CacheConfig c;  // 64-byte lines, 1 cycle per bank access
        c.size_kib = 1024;
        c.ways = 16;
        c.latency = 20;
        c.mshrs = 64;
        c.banks = 8;
        return c;
    }();
    DramConfig dram;
    TreeletConfig treelets;
    ShadingConfig shading;
    BuildUnitConfig build_unit;  ///< moving scenes: each frame's build or refit (rtl_model/build_unit)

    /// The pipeline operations of `kind` go to. Adding an operation kind adds a PipelineConfig
    /// member, its visit() line and a case here (docs/accel.md, "Adding a structure"); a kind with
    /// no pipeline is an error naming it.
    const PipelineConfig& pipeline(OpKind kind) const;
    PipelineConfig& pipeline(OpKind kind) { return const_cast<PipelineConfig&>(std::as_const(*this).pipeline(kind)); }
    /// True when the SystemC model times this level (approx, detailed).
    bool timed() const { return fidelity == Fidelity::approx || fidelity == Fidelity::detailed; }

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
        v.section("obb", obb);
        v.section("sphere", sphere);
        v.section("capsule", capsule);
        v.section("mailbox", mailbox);
        v.section("l1", l1);
        v.section("l2", l2);
        v.section("dram", dram);
        v.section("treelets", treelets);
        v.section("shading", shading);
        v.section("build_unit", build_unit);
    }
};

/// What the step-demand function needs of this machine for a structure issuing `kinds`;
/// throws rtsim::Error naming a kind the machine has no pipeline for.
inline StepCosts step_costs(const ModelConfig& config, const std::vector<OpKind>& kinds) {
    return StepCosts::of(config.traversal, kinds, [&](OpKind k) -> const PipelineConfig& { return config.pipeline(k); });
}

/// The model's cross-field rules (cache geometry, line sizes, DRAM address fields and timing);
/// throws rtsim::Error naming the field and what to change. Ranges are checked by the harness's
/// visitor over the whole tree.
void validate_model(const ModelConfig& config);

}  // namespace rtsim
