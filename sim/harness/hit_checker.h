#pragma once
// The hit checker (docs/architecture.md, rule 2): every ray the model finishes is compared with the
// trace's reference hit (primitive id and the bits of t) and reference work (every traced field of
// traces/common/work_counts.h; with a mailbox, the tests it skipped counted back:
// WorkCounts::without_mailbox). Mismatches are counted, the first ones listed, and make rtsim-sim
// exit non-zero. It also keeps the per-ray latency histogram and reports progress.
#include <cstdint>
#include <functional>
#include <vector>

#include <nlohmann/json.hpp>
#include <systemc>

#include "rtl_model/common/stats.h"
#include "rtl_model/common/interfaces.h"
#include "sim/harness/latency_histogram.h"
#include "sim/harness/trace_stream.h"

namespace rtsim {

class HitChecker : public sc_core::sc_module, public RaySinkIf {
public:
    using Progress = std::function<void(uint64_t done, uint64_t total)>;
    HitChecker(sc_core::sc_module_name name, ReferenceSource& reference, uint64_t total, Progress progress = {});

    void ray_done(const RayResult& r) override;
    /// With a packet reference, a packet's work is checked against the structure's reference packet
    /// loop over the same rays (hits against the trace as ever; see set_packet_reference).
    void packet_done(const RayResult* results, const Ray* rays, const TraversalMode* modes, uint32_t n) override;

    /// The reference packet loop (Accel::trace_packet): each ray's hit and work when traced in
    /// one packet with the others. Packets change the work a ray does, never its closest hit;
    /// an any-hit ray may stop at another occluder than alone (visit order), so it is checked for
    /// occlusion against the trace and for its primitive against the packet loop.
    using PacketReference = std::function<void(const Ray*, const TraversalMode*, uint32_t, Hit*, WorkCounts*)>;
    void set_packet_reference(PacketReference reference) { m_packet_reference = std::move(reference); }

    /// A ray whose walk the trace was not traced with (an any-hit ray in another child order,
    /// StepOptions::anyhit_order): its occlusion is checked against the trace, its hit primitive
    /// and work are the model's own (the stepper tests check them against trace()).
    void occlusion_done(const RayResult& r);
    /// The run walks any-hit rays in another child order than the trace's: ray_done() checks
    /// each any-hit ray by occlusion_done() (the levels that run such an order set it).
    void set_reordered_anyhit(bool reordered) { m_reordered_anyhit = reordered; }

    uint64_t checked() const { return m_checked; }
    uint64_t hit_mismatches() const { return m_hit_mismatches; }
    uint64_t work_mismatches() const { return m_work_mismatches; }
    const LatencyHistogram& latency() const { return m_latency; }
    /// The model's work over every ray checked (equal to the reference's when there are no mismatches).
    const WorkTotals& work_totals() const { return m_work; }
    nlohmann::json to_json() const;
    /// Optional per-ray hook (the timeline records ray residency through it).
    std::function<void(const RayResult&)> on_ray;

private:
    void check(const RayResult& r, const HitRecord& ref_hit, const WorkRecord& ref_work);
    /// An any-hit ray walked in the run's order: its work beside the trace's (validation.reordered_anyhit).
    void count_reordered(const RayResult& r);

    PacketReference m_packet_reference;
    bool m_reordered_anyhit = false;
    ReferenceSource& m_reference;
    uint64_t m_total;
    Progress m_progress;
    uint64_t m_checked = 0, m_hit_mismatches = 0, m_work_mismatches = 0;
    nlohmann::json m_examples = nlohmann::json::array();
    LatencyHistogram m_latency;
    WorkTotals m_work;
    WorkTotals m_reordered_own, m_reordered_reference;  ///< any-hit rays walked in another order
    uint64_t m_reordered = 0;
};

/// Compares one result with the reference; returns "" when equal, else a description.
std::string compare_with_reference(const RayResult& r, const HitRecord& ref_hit, const WorkRecord& ref_work,
                                   bool* hit_differs);

/// stats.json "validation", declared once.
const StatBlock& validation_stats();

}  // namespace rtsim
