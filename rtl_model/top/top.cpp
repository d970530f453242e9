#include "rtl_model/top/top.h"

#include <algorithm>

#include "rtl_model/top/model_stats.h"
#include "traces/common/error.h"

namespace rtsim {

/// Memory where every access hits at the L1 latency: the performance upper bound.
class IdealMemory : public sc_core::sc_module, public MemIf {
public:
    IdealMemory(sc_core::sc_module_name name, Cycle latency) : sc_core::sc_module(name), m_latency(latency) {}
    Cycle access(const MemRequest& req) override {
        if (req.prefetch) return req.time;  // nothing to prefetch into: every access hits
        MemCounters& c = m_stats[req.kind];
        (req.write ? c.writes : c.reads) += 1;
        (req.write ? c.write_bytes : c.read_bytes) += req.bytes;
        if (!req.write) ++c.read_hits;
        return req.time + m_latency;
    }
    nlohmann::json stats_json() const {
        nlohmann::json j;
        StatsWriter(ideal_memory_stats(), j).merge(m_stats.to_json()).done();
        return j;
    }

private:
    Cycle m_latency;
    MemStats m_stats;
};

Top::Top(sc_core::sc_module_name name, const ModelConfig& config, const Accel& accel, const StepOptions& step,
         const MemoryMap& map, RayStream& rays, RaySinkIf& sink, const WorkloadFeatures& features,
         const ShadingInputs* shading)
    : sc_core::sc_module(name),
      m_config(config),
      m_unit_context{config.quantum_cycles, config.dispatch.latency, config.treelets.idle_poll_cycles},
      m_steppers(accel, step) {
    require(config.traversal.ray_contexts > 0 && config.traversal.stack_entry_bytes > 0,
            "model: the config is not resolved (traversal.ray_contexts and stack_entry_bytes 0); the run's "
            "resolution step derives them");
    m_unit_context.line_bytes = config.l1.line_bytes;
    m_dispatch = std::make_unique<Dispatch>("dispatch", config.dispatch, config.traversal.units, rays);
    build_memory();
    build_pipelines(accel);
    build_treelets(accel, map);
    build_shading(shading, sink);
    // Detailed (quantum 1) with private pipelines: a unit's operations phases touch only its own
    // blocks, so they need not wait for SystemC time (docs/model.md, "Detailed level").
    bool private_ops = true;
    for (const auto& pipes : m_pipes)
        for (const auto& p : pipes) private_ops = private_ops && !p->shared();
    m_unit_context.sync_private_steps =
        !(m_config.fidelity == Fidelity::detailed && private_ops && !m_config.treelets.enabled);
    const UnitSetup setup{config.traversal, m_unit_context, map, m_steppers, step_costs(config, accel.op_kinds()),
                          m_treelets.get()};
    const UnitKind& kind = config.traversal.kind();
    for (uint32_t u = 0; u < config.traversal.units; ++u) {
        auto unit = kind.make_unit(("tu" + std::to_string(u)).c_str(), setup, u);
        unit->rays(*m_dispatch);
        if (m_shading) unit->sink(*m_shading);
        else unit->sink(sink);
        if (m_ideal) unit->mem(*m_ideal);
        else unit->mem(*m_l1[u]);
        for (int k = 0; k < kOpKindCount; ++k) {
            const PipelineSet& set = m_pipes[size_t(k)];
            if (!set.empty()) unit->pipes[size_t(k)](*set[set.size() == 1 ? 0 : u]);
        }
        if (m_ray_buffer) unit->ray_buffer(*m_ray_buffer);
        m_units.push_back(std::move(unit));
    }
    m_instantiated.push_back({{"block", "traversal"}, {"instantiated", true},
                              {"why", traversal_units_text(config.traversal) + ", " + accel.kind() + " structure"}});
    m_instantiated.push_back({{"block", "occlusion_early_exit"}, {"instantiated", features.occlusion_rays > 0},
                              {"why", features.occlusion_rays ? std::to_string(features.occlusion_rays) +
                                                                    " any-hit (shadow) rays stop at their first hit"
                                                              : "no any-hit (shadow) rays in the trace"}});
}

Top::~Top() = default;

void Top::build_shading(const ShadingInputs* shading, RaySinkIf& sink) {
    const ShadingConfig& c = m_config.shading;
    if (!c.enabled || !shading) {
        m_instantiated.push_back({{"block", "shading"}, {"instantiated", false},
                                  {"why", c.enabled ? "the trace has no shading sections (version 4 or older)"
                                                    : "shading.enabled is false: the RT unit alone is timed"}});
        return;
    }
    m_shading = std::make_unique<ShadingBlock>("shading", c, *shading, sink, m_l2.get(), m_config.interconnect_latency,
                                               m_config.fidelity == Fidelity::detailed);
    m_instantiated.push_back({{"block", "shading"}, {"instantiated", true},
                              {"why", std::to_string(c.cores) + " SIMT shader cores (" + std::to_string(c.warp_width) +
                                          " lanes), " + kFrameLoopChoices.name(c.frame_loop) + " frame loop, " +
                                          std::to_string(shading->shaders) + " hit shaders"}});
    m_instantiated.push_back({{"block", "texture_cache"}, {"instantiated", !m_shading->tex_caches().empty()},
                              {"why", !shading->has_textures() ? "no material samples a texture"
                                      : m_shading->tex_caches().empty()
                                          ? "ideal memory"
                                          : std::to_string(c.cores) + " x " + std::to_string(c.tex_cache.size_kib) +
                                                " KiB, " + std::to_string(shading->textures.size()) + " textures"}});
    m_instantiated.push_back({{"block", "shade_reorder"}, {"instantiated", c.reorder != ShadeReorder::none},
                              {"why", c.reorder == ShadeReorder::none
                                          ? "shading.reorder is none"
                                          : std::string("hits sorted by ") + kShadeReorderChoices.name(c.reorder) +
                                                " in windows of " + std::to_string(c.reorder_window)}});
}

Cycle Top::frame_cycles() const { return m_shading ? m_shading->frame_end(total_cycles()) : total_cycles(); }

MemIf& Top::shared_memory() {
    if (m_l2) return *m_l2;
    return *m_ideal;
}

void Top::build_memory() {
    const ModelConfig& c = m_config;
    if (c.ideal_memory) {
        m_ideal = std::make_unique<IdealMemory>("ideal_memory", c.l1.latency);
        m_instantiated.push_back({{"block", "memory"}, {"instantiated", false},
                                  {"why", kIdealMemoryWhy}});
        return;
    }
    // The detailed level adds exact per-cycle cache banks (its units synchronise every cycle).
    // DRAM banks and row buffers are modelled at both timed levels (dram.model).
    const bool detailed = c.fidelity == Fidelity::detailed;
    m_dram = std::make_unique<Dram>("dram", c.dram);
    // The L2 is reached out of time order (within a quantum at approx; at both levels by L1
    // misses stamped with the cycle their MSHR frees): its MSHRs keep their booked intervals and
    // an earlier request back-fills them (docs/model.md); the private L1s' are a free list.
    m_l2 = std::make_unique<Cache>("l2", c.l2, false, 0, detailed, ServedBy::l2);
    m_l2->backfill_misses();
    m_l2->next(*m_dram);
    for (uint32_t u = 0; u < c.traversal.units; ++u) {
        m_l1.push_back(std::make_unique<Cache>(("l1_" + std::to_string(u)).c_str(), c.l1, true, c.interconnect_latency,
                                               detailed));
        m_l1.back()->next(*m_l2);
    }
    m_instantiated.push_back({{"block", "memory"}, {"instantiated", true},
                              {"why", "per-unit L1, shared " + std::to_string(c.l2.banks) + "-bank L2, " +
                                          std::to_string(c.dram.channels) + " DRAM channels" +
                                          (c.dram.model == DramModel::banks
                                               ? " of " + std::to_string(c.dram.banks) + " banks (" +
                                                     kPagePolicyChoices.name(c.dram.page_policy) + " page)"
                                               : std::string(" (bandwidth calendars)")) +
                                          (detailed ? ", L2 MSHRs" : std::string())}});
}

void Top::build_pipelines(const Accel& accel) {
    // A pipeline for each operation kind the structure issues; the others are not built.
    const std::vector<OpKind> used = accel.op_kinds();
    const bool exact = m_config.fidelity == Fidelity::detailed;
    for (int k = 0; k < kOpKindCount; ++k) {
        const OpKind kind = OpKind(k);
        const char* base = op_kind_name(kind);
        const bool needed = std::find(used.begin(), used.end(), kind) != used.end();
        if (needed) {
            const PipelineConfig& c = m_config.pipeline(kind);
            if (c.shared()) {
                m_pipes[size_t(k)].push_back(std::make_unique<Pipeline>((std::string(base) + "_pool").c_str(), c, true, exact));
            } else {
                for (uint32_t u = 0; u < m_config.traversal.units; ++u)
                    m_pipes[size_t(k)].push_back(
                        std::make_unique<Pipeline>((std::string(base) + "_" + std::to_string(u)).c_str(), c, false, exact));
            }
        }
        std::string why;
        if (kind == OpKind::anyhit)
            why = needed ? "the structure has alpha-MASK triangles: alpha test stage" : "no alpha-MASK triangle in the structure";
        else if (kind == OpKind::transform)
            why = needed ? "two-level structure: instance transforms" : "single-level structure: no instance transforms";
        else
            why = std::string("the ") + accel.kind() + " structure " + (needed ? "issues" : "issues no") + " " + base +
                  " operations";
        m_instantiated.push_back({{"block", kind == OpKind::transform ? "instance_transform" : base},
                                  {"instantiated", needed}, {"why", why}});
    }
}

void Top::build_treelets(const Accel& accel, const MemoryMap& map) {
    const TreeletConfig& t = m_config.treelets;
    // Prefetching needs the partition and the footprint table, not the queues (Chou et al.
    // prefetch on a warp-based RT unit without treelet queues); scheduling needs both.
    const bool prefetch = t.prefetch && !m_ideal;
    if (t.enabled || prefetch) {
        LocalityPartition partition = accel.partition(uint64_t(t.treelet_kib) * 1024);
        std::unique_ptr<TreeletFootprints> footprints;
        if (prefetch)
            footprints = std::make_unique<TreeletFootprints>(
                uint32_t(partition.treelets.size()), m_config.l1.line_bytes, t.prefetch_lines,
                t.prefetch_into == PrefetchInto::l1 ? ServedBy::l1 : ServedBy::l2);
        m_treelets = std::make_unique<TreeletMap>(std::move(partition), std::move(footprints));
    }
    const std::string prefetch_why =
        prefetch ? std::string(", treelet prefetch into ") + kPrefetchIntoChoices.name(t.prefetch_into) : std::string();
    if (!t.enabled) {
        m_instantiated.push_back({{"block", "ray_buffer"}, {"instantiated", false},
                                  {"why", "treelets.enabled is false: rays go from dispatch straight to the units"}});
        if (prefetch)
            m_instantiated.push_back(
                {{"block", "treelet_prefetch"}, {"instantiated", true},
                 {"why", std::to_string(m_treelets->treelets()) + " treelets of at most " +
                             std::to_string(t.treelet_kib) + " KiB prefetched when a ray enters one, without treelet "
                             "queues" + prefetch_why}});
        return;
    }
    const TraversalConfig& tc = m_config.traversal;
    const uint32_t consumers = tc.units * tc.kind().treelet_consumers(tc);
    m_ray_buffer = std::make_unique<RayBuffer>("ray_buffer", t, *m_treelets, map, m_steppers, tc.units, tc.contexts(),
                                               consumers,
                                               ray_state_bytes(tc.stack_entries, tc.stack_entry_bytes,
                                                               m_config.mailbox.entries * MailboxConfig::kEntryBytes),
                                               m_config.quantum_cycles);
    m_ray_buffer->rays(*m_dispatch);
    if (m_ideal) m_ray_buffer->mem(*m_ideal);
    else m_ray_buffer->mem(*m_l2);
    m_instantiated.push_back({{"block", "ray_buffer"}, {"instantiated", true},
                              {"why", std::to_string(m_treelets->treelets()) + " treelets of at most " +
                                          std::to_string(t.treelet_kib) + " KiB, " + std::to_string(t.buffer_kib) +
                                          " KiB ray buffer (" + std::to_string(m_ray_buffer->capacity_rays()) +
                                          " rays), policy " + kTreeletPolicyChoices.name(t.policy) + prefetch_why}});
}

void Top::warm(uint32_t unit, uint64_t addr, uint32_t bytes) {
    if (!m_l2) return;
    if (unit >= m_l1.size()) {
        m_l2->warm(addr, bytes);
        return;
    }
    // Line by line, as the L1 forwards misses: the L2 sees (and refreshes) only the L1's misses.
    Cache& l1 = *m_l1[unit];
    const uint64_t line = l1.line_bytes(), end = addr + std::max<uint32_t>(bytes, 1);
    for (uint64_t lo = addr / line * line; lo < end; lo += line)
        if (!l1.warm(lo, uint32_t(line))) m_l2->warm(lo, uint32_t(line));
}

MemoryTotals Top::memory_totals() const {
    MemoryTotals t;
    for (const auto& l1 : m_l1) t.l1 += l1->stats().total();
    if (m_l2) t.l2 = m_l2->stats().total();
    if (m_dram) t.dram = m_dram->stats().total();
    return t;
}

Cycle Top::total_cycles() const {
    Cycle t = 0;
    for (const auto& u : m_units) t = std::max(t, u->finish_cycle());
    return t;
}

nlohmann::json Top::stats_json() const {
    const Cycle total = total_cycles();
    nlohmann::json j;
    j["dispatch"] = m_dispatch->stats_json();
    for (const auto& u : m_units) j["units"][u->basename()] = u->stats_json(total);
    for (int k = 0; k < kOpKindCount; ++k)
        for (const auto& p : m_pipes[size_t(k)]) j[op_kind_name(OpKind(k))][p->basename()] = p->stats_json(total);
    if (m_ideal) j["ideal_memory"] = m_ideal->stats_json();
    if (m_ray_buffer) j["ray_buffer"] = m_ray_buffer->stats_json();
    else if (m_treelets && m_treelets->footprints())
        j["treelet_prefetch"] = {{"treelets", m_treelets->partition_json()}, {"prefetch", m_treelets->prefetch_json()}};
    for (const auto& l1 : m_l1) j["l1"][l1->basename()] = l1->stats_json(total);
    if (m_l2) j["l2"] = m_l2->stats_json(total, true);
    if (m_dram) j["dram"] = m_dram->stats_json(total, m_config.clock_ghz);
    j["cycle_accounting"] = cycle_accounting_json(total);
    j["utilization"] = utilization_json(total);
    if (m_shading) j["shading"] = m_shading->stats_json(total, m_config.clock_ghz);
    check_model_stats(j, m_config.traversal.model);
    return j;
}

nlohmann::json Top::cycle_accounting_json(Cycle total) const {
    CycleAccount all;
    for (const auto& u : m_units) all += u->cycle_account(total);
    const double context_cycles = double(all.total());
    const nlohmann::json by_use = all.to_json();
    nlohmann::json fractions = nlohmann::json::object();
    for (auto it = by_use.begin(); it != by_use.end(); ++it)
        fractions[it.key()] = context_cycles > 0 ? it.value().get<double>() / context_cycles : 0.0;
    nlohmann::json j;
    StatsWriter(cycle_accounting_stats(), j)
        .set("context_cycles", all.total())
        .set("by_use", by_use)
        .set("fractions", fractions)
        .done();
    return j;
}

nlohmann::json Top::utilization_json(Cycle total) const {
    // Every shared resource as one total over the run and over time (docs/stats.md).
    nlohmann::json j = nlohmann::json::object();
    const double cycles = double(std::max<Cycle>(total, 1));
    StatsWriter w(utilization_stats(), j);
    auto add = [&](const std::string& name, const UsageSeries& use, double capacity) {
        w.set(name.c_str(), nlohmann::json{{"mean", capacity > 0 ? double(use.total()) / cycles / capacity : 0.0},
                                           {"over_time", use.to_json(capacity)}});
    };
    for (int k = 0; k < kOpKindCount; ++k) {
        if (m_pipes[size_t(k)].empty()) continue;
        UsageSeries use;
        double capacity = 0;
        for (const auto& p : m_pipes[size_t(k)]) {
            use += p->issue_use();
            capacity += p->issue_capacity();
        }
        add(std::string("pipe_") + op_kind_name(OpKind(k)), use, capacity);
    }
    if (!m_l1.empty()) {
        UsageSeries banks, mshrs;
        double bank_capacity = 0, mshr_capacity = 0;
        for (const auto& l1 : m_l1) {
            banks += l1->bank_use();
            mshrs += l1->mshr_use();
            bank_capacity += l1->bank_capacity();
            mshr_capacity += l1->mshrs();
        }
        add("l1_banks", banks, bank_capacity);
        add("l1_mshrs", mshrs, mshr_capacity);
    }
    if (m_l2) {
        add("l2_banks", m_l2->bank_use(), m_l2->bank_capacity());
        add("l2_mshrs", m_l2->mshr_use(), m_l2->mshrs());
    }
    if (m_dram) add("dram_bandwidth", m_dram->bytes_use(), m_dram->peak_bytes_per_cycle());
    return j;
}

}  // namespace rtsim
