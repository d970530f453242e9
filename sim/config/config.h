#pragma once
// The one config tree of the simulator (DESIGN rule 5): plain structs with defaults and units.
// Each struct lists its fields once in visit() with name, unit, range and a one-line doc; the
// JSON reader, writer, schema dump (for the Python dataclasses) and validate() are all visitors,
// so a field cannot be documented, defaulted or range-checked in one place and not another.
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

namespace rtsim {

/// A ray-box or ray-triangle pipeline (timing only; the arithmetic is traces/isect/).
struct PipelineConfig {
    uint32_t latency = 8;              ///< cycles from issue to result
    uint32_t initiation_interval = 1;  ///< cycles between issues into one pipeline
    uint32_t width = 1;                ///< tests per issue (boxes per issue for the box pipeline)
    std::string sharing = "private";   ///< "private": one pipeline per unit; "shared": a pool
    uint32_t shared_count = 4;         ///< pipelines in the shared pool (sharing = "shared")

    template <class V>
    void visit(V& v) {
        v.field("latency", latency, "cycles", "Cycles from issue to result", 1, 1000);
        v.field("initiation_interval", initiation_interval, "cycles", "Cycles between two issues into one pipeline", 1, 1000);
        v.field("width", width, "tests", "Tests per issue (a node has 2 child boxes: width 2 tests a node in one issue)", 1, 64);
        v.choice("sharing", sharing, {"private", "shared"}, "One pipeline per traversal unit, or a pool shared by all units");
        v.field("shared_count", shared_count, "pipelines", "Pipelines in the shared pool (sharing = shared)", 1, 1024);
    }
};

struct CacheConfig {
    uint32_t size_kib = 16;   ///< capacity
    uint32_t ways = 4;        ///< associativity
    uint32_t line_bytes = 64; ///< line size
    uint32_t latency = 4;     ///< hit latency in cycles
    uint32_t mshrs = 8;       ///< outstanding misses (miss status holding registers)
    uint32_t banks = 1;       ///< independently accessible banks (line-interleaved)
    uint32_t bank_cycles = 1; ///< cycles a bank is busy per access

    template <class V>
    void visit(V& v) {
        v.field("size_kib", size_kib, "KiB", "Capacity", 1, 1u << 20);
        v.field("ways", ways, "ways", "Associativity (LRU replacement)", 1, 64);
        v.field("line_bytes", line_bytes, "bytes", "Line size (power of two, same at every level)", 16, 1024);
        v.field("latency", latency, "cycles", "Hit latency", 1, 1000);
        v.field("mshrs", mshrs, "entries", "Outstanding misses; a miss waits for a free MSHR", 1, 1024);
        v.field("banks", banks, "banks", "Line-interleaved banks, each serving one access per bank_cycles", 1, 256);
        v.field("bank_cycles", bank_cycles, "cycles", "Cycles a bank is busy per access", 1, 100);
    }
};

struct DramConfig {
    uint32_t channels = 2;          ///< independent channels, interleaved every interleave_bytes
    uint32_t bytes_per_cycle = 16;  ///< peak bandwidth of one channel in bytes per core cycle
    uint32_t latency = 120;         ///< cycles from request to first data, unloaded
    uint32_t interleave_bytes = 256;///< address interleaving granule across channels
    // Banks and row buffers: used by fidelity = "detailed" only (docs/model.md, detailed DRAM).
    uint32_t banks = 16;            ///< banks per channel, each with one row buffer
    uint32_t row_bytes = 2048;      ///< row (page) size per bank
    std::string page_policy = "open";  ///< "open": rows stay open; "close": auto-precharge
    uint32_t t_rcd = 14;            ///< activate to column command, core cycles
    uint32_t t_rp = 14;             ///< precharge, core cycles
    uint32_t t_cas = 14;            ///< column command to first data, core cycles

    template <class V>
    void visit(V& v) {
        v.field("channels", channels, "channels", "Independent DRAM channels", 1, 64);
        v.field("bytes_per_cycle", bytes_per_cycle, "B/cycle", "Peak bandwidth per channel, bytes per core cycle", 1, 4096);
        v.field("latency", latency, "cycles", "Unloaded access latency (request to data; at detailed: to a closed bank)", 1, 100000);
        v.field("interleave_bytes", interleave_bytes, "bytes", "Channel interleaving granule (power of two, >= line size)", 64, 1u << 20);
        v.field("banks", banks, "banks", "Banks per channel, one row buffer each (detailed only)", 1, 256);
        v.field("row_bytes", row_bytes, "bytes", "Row (page) size of a bank (power of two; detailed only)", 64, 1u << 20);
        v.choice("page_policy", page_policy, {"open", "close"}, "Row buffer policy: keep rows open (row hits) or precharge after each access (detailed only)");
        v.field("t_rcd", t_rcd, "cycles", "Activate to column command, core cycles (detailed only)", 0, 10000);
        v.field("t_rp", t_rp, "cycles", "Precharge time, core cycles (detailed only)", 0, 10000);
        v.field("t_cas", t_cas, "cycles", "Column command to first data, core cycles (detailed only)", 0, 10000);
    }
};

struct TraversalConfig {
    uint32_t units = 8;              ///< MIMD traversal units
    uint32_t ray_contexts = 16;      ///< rays in flight per unit, each advancing independently
    uint32_t stack_entries = 8;      ///< on-chip traversal stack entries per ray; deeper entries spill
    uint32_t stack_entry_bytes = 8;  ///< bytes per stack entry (node reference + entry distance)
    uint32_t issue_cycles = 1;       ///< cycles the unit's scheduler needs per traversal step

    template <class V>
    void visit(V& v) {
        v.field("units", units, "units", "MIMD traversal units", 1, 4096);
        v.field("ray_contexts", ray_contexts, "rays", "Ray contexts per unit (rays in flight)", 1, 4096);
        v.field("stack_entries", stack_entries, "entries", "On-chip stack entries per ray; overflow spills to memory", 1, 64);
        v.field("stack_entry_bytes", stack_entry_bytes, "bytes", "Bytes per stack entry (spill traffic)", 4, 64);
        v.field("issue_cycles", issue_cycles, "cycles", "Scheduler cycles per traversal step of one unit", 1, 100);
    }
};

struct DispatchConfig {
    uint32_t chunk_rays = 16384;          ///< rays read from the trace at a time (host memory bound)
    uint32_t latency = 2;                 ///< cycles to hand a ray to a free context (plus the ray fetch)
    std::string policy = "interleaved";   ///< how rays are spread over the units
    uint32_t block_rays = 1;              ///< consecutive rays dealt to one unit (interleaved)

    template <class V>
    void visit(V& v) {
        v.field("chunk_rays", chunk_rays, "rays", "Rays streamed from the trace file per chunk", 64, 1u << 24);
        v.field("latency", latency, "cycles", "Cycles to assign a ray to a free context, before its fetch", 0, 1000);
        v.choice("policy", policy, {"interleaved", "on_demand"}, "interleaved: rays dealt to units in turn, blocks of block_rays, idle units steal; on_demand: the next ray to whichever unit asks first (depends on quantum_cycles)");
        v.field("block_rays", block_rays, "rays", "Consecutive rays dealt to one unit at a time (interleaved policy)", 1, 1u << 20);
    }
};

/// Treelet scheduling with ray buffers (Aila & Karras 2010; STRaTA, Kopta et al. 2013).
struct TreeletConfig {
    bool enabled = false;             ///< queue rays per treelet in the ray buffer
    uint32_t treelet_kib = 16;        ///< byte budget per treelet (nodes + leaf triangles)
    uint32_t buffer_kib = 512;        ///< ray buffer SRAM capacity
    std::string policy = "largest";   ///< which queue a free unit runs next
    uint32_t threshold = 64;          ///< rays a queue needs before it is worth running
    uint32_t latency = 4;             ///< ray buffer SRAM access latency
    uint32_t bytes_per_cycle = 512;   ///< ray buffer SRAM bandwidth (banked: 8 units x 64 B)
    uint32_t idle_poll_cycles = 32;   ///< how often an idle unit looks for work again
    uint32_t max_rays_in_flight = 0;  ///< rays admitted at once (0: what the SRAM and contexts hold)

    template <class V>
    void visit(V& v) {
        v.flag("enabled", enabled, "Treelet scheduling: rays queue per treelet in the ray buffer SRAM");
        v.field("treelet_kib", treelet_kib, "KiB", "Byte budget per treelet (nodes and their leaf triangles)", 1, 1u << 20);
        v.field("buffer_kib", buffer_kib, "KiB", "Ray buffer SRAM capacity; rays beyond it overflow to DRAM", 1, 1u << 22);
        v.choice("policy", policy, {"largest", "oldest", "round_robin"}, "Queue a free unit runs next: largest queue, oldest waiting ray, or round robin");
        v.field("threshold", threshold, "rays", "Queues of at least this many rays are preferred (oldest, round_robin); shorter ones run only when no queue is that long. No effect with largest", 1, 1u << 20);
        v.field("latency", latency, "cycles", "Ray buffer SRAM access latency", 1, 1000);
        v.field("bytes_per_cycle", bytes_per_cycle, "B/cycle", "Ray buffer SRAM bandwidth", 1, 4096);
        v.field("idle_poll_cycles", idle_poll_cycles, "cycles", "How often a unit with no rays looks for a queue again", 1, 100000);
        v.field("max_rays_in_flight", max_rays_in_flight, "rays", "Rays admitted into the machine at once; beyond what the SRAM holds, queues overflow to DRAM (0: SRAM capacity plus the ray contexts, never overflows)", 0, 1u << 30);
    }
};

/// Statistical sampling (docs/fidelity.md): simulate a stratified sample of clusters of rays, each
/// warm-up then measured rays, and estimate the full run's cycles with a 95% confidence interval
/// (SMARTS, Wunderlich et al. 2003). Off unless fraction or count is set; needs a timed level.
struct SamplingConfig {
    double fraction = 0.0;      ///< fraction of the trace's rays simulated (warm-up included); 0: off
    uint32_t count = 0;         ///< rays simulated, instead of a fraction; 0: off
    uint32_t clusters = 30;     ///< strata, one cluster of rays each (fewer if the sample is small)
    uint32_t warmup_rays = 0;   ///< warm-up rays per cluster; 0: max(2 x rays in flight, L2 lines / 8)
    uint32_t seed = 1;          ///< picks each cluster's offset within its stratum

    bool enabled() const { return fraction > 0 || count > 0; }

    template <class V>
    void visit(V& v) {
        v.field("fraction", fraction, "fraction", "Fraction of the trace's rays to simulate, warm-up included (0: no sampling)", 0.0, 1.0);
        v.field("count", count, "rays", "Rays to simulate instead of a fraction (0: no sampling)", 0, 2147483647.0);
        v.field("clusters", clusters, "clusters", "Strata of the trace, one sampled cluster each (fewer when the sample cannot hold them with their warm-up)", 2, 100000);
        v.field("warmup_rays", warmup_rays, "rays", "Warm-up rays simulated before each cluster's measured rays (0: automatic, docs/fidelity.md)", 0, 1u << 24);
        v.field("seed", seed, "seed", "Seed of each cluster's random offset within its stratum", 0, 2147483647.0);
    }
};

struct SimConfig {
    double clock_ghz = 1.0;          ///< converts cycles to seconds
    std::string fidelity = "approx"; ///< functional | analytic | approx | detailed (docs/fidelity.md)
    uint32_t quantum_cycles = 256;   ///< how far a unit may run ahead of SystemC time
    uint32_t interconnect_latency = 8;  ///< L1 to L2 one-way cycles
    bool ideal_memory = false;       ///< every access hits in L1 (upper bound on performance)
    DispatchConfig dispatch;
    TraversalConfig traversal;
    PipelineConfig box{8, 1, 2, "private", 4};
    PipelineConfig triangle{20, 1, 1, "private", 4};
    PipelineConfig anyhit{10, 1, 1, "private", 4};
    CacheConfig l1{16, 4, 64, 4, 8, 1, 1};
    CacheConfig l2{1024, 16, 64, 20, 32, 8, 1};
    DramConfig dram;
    TreeletConfig treelets;
    SamplingConfig sampling;

    template <class V>
    void visit(V& v) {
        v.field("clock_ghz", clock_ghz, "GHz", "Core clock: converts cycles to seconds", 0.001, 100.0);
        v.choice("fidelity", fidelity, {"functional", "analytic", "approx", "detailed"}, "Simulation level: functional (counts only), analytic (cache simulation + roofline), approx (timed SystemC model) or detailed (per-cycle arbitration, L2 MSHRs, DRAM banks)");
        v.field("quantum_cycles", quantum_cycles, "cycles", "How far a traversal unit may run ahead of the others (temporal decoupling)", 1, 1u << 20);
        v.field("interconnect_latency", interconnect_latency, "cycles", "One-way latency between an L1 and the L2", 0, 10000);
        v.flag("ideal_memory", ideal_memory, "Every access hits in L1 at L1 latency: the upper bound on performance");
        v.section("dispatch", dispatch);
        v.section("traversal", traversal);
        v.section("box", box);
        v.section("triangle", triangle);
        v.section("anyhit", anyhit);
        v.section("l1", l1);
        v.section("l2", l2);
        v.section("dram", dram);
        v.section("treelets", treelets);
        v.section("sampling", sampling);
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
