#include "rtl_model/traversal/traversal_unit.h"

#include <algorithm>

namespace rtsim {

TraversalUnit::TraversalUnit(sc_core::sc_module_name name, const SimConfig& config, const MemoryImage& image,
                             uint32_t index)
    : sc_core::sc_module(name), m_config(config), m_image(image), m_index(index), m_contexts(config.traversal.ray_contexts) {
    SC_THREAD(run);
}

void TraversalUnit::run() {
    for (uint32_t c = 0; c < m_contexts.size(); ++c) start_ray(c, 0);
    while (!m_events.empty()) {
        Event e = m_events.top();
        m_events.pop();
        // The scheduler takes one step per issue_cycles.
        Cycle t = std::max(e.time, m_sched_free);
        m_sched_free = t + m_config.traversal.issue_cycles;
        sync(t);
        advance(e.context, t);
    }
}

void TraversalUnit::sync(Cycle t) {
    // Temporal decoupling: run ahead of SystemC time by at most a quantum, then let others catch up.
    if (t < m_synced + m_config.quantum_cycles) return;
    uint64_t now = sc_core::sc_time_stamp().value();
    if (t > now) wait(sc_core::sc_time::from_value(t - now));
    m_synced = t;
    ++m_syncs;
}

bool TraversalUnit::start_ray(uint32_t c, Cycle t) {
    RayJob job;
    if (!rays->next_ray(&job)) return false;
    Context& ctx = m_contexts[c];
    ctx.trav.begin(job.ray, job.any_hit ? TraversalMode::any_hit : TraversalMode::closest_hit);
    if (!ray_is_valid(job.ray)) ++m_rejected;
    ctx.ray_id = job.id;
    ctx.start = t;
    ctx.local_stack = ctx.spilled = 0;
    ctx.active = true;
    if (m_active++ == 0) m_busy_since = t;
    // The ray record is read from memory before traversal starts.
    Cycle ready = mem->access({MemoryMap::ray(job.id), sizeof(RayRecord), false, DataKind::ray,
                               t + m_config.dispatch.latency});
    ctx.phase = Phase::fetch_ray;
    schedule(c, ready);
    return true;
}

void TraversalUnit::advance(uint32_t c, Cycle t) {
    Context& ctx = m_contexts[c];
    ++m_steps;
    switch (ctx.phase) {
        case Phase::fetch_ray:
        case Phase::step:
            step(c, t);
            return;
        case Phase::boxes: {
            const uint32_t node = ctx.trav.node_index();
            Cycle ready = box->issue(t, 2);
            int before = ctx.trav.stack_size();
            ctx.trav.visit_node(m_image.nodes[node]);
            ctx.phase = Phase::step;
            schedule(c, stack_traffic(c, before, t, ready));
            return;
        }
        case Phase::triangles: {
            const uint32_t first = ctx.trav.leaf_first(), count = ctx.trav.leaf_count();
            Cycle ready = triangle->issue(t, count);
            uint32_t anyhit_before = ctx.trav.work().anyhit_calls;
            int before = ctx.trav.stack_size();
            ctx.trav.visit_leaf(&m_image.triangles[first]);
            uint32_t alpha_tests = ctx.trav.work().anyhit_calls - anyhit_before;
            if (alpha_tests) ready = anyhit->issue(ready, alpha_tests);
            ctx.phase = Phase::step;
            schedule(c, stack_traffic(c, before, t, ready));
            return;
        }
    }
}

void TraversalUnit::step(uint32_t c, Cycle t) {
    Context& ctx = m_contexts[c];
    switch (ctx.trav.step()) {
        case Traversal::Step::node: {
            Cycle ready = mem->access({MemoryMap::node(ctx.trav.node_index()), sizeof(HwNode), false, DataKind::node, t});
            ctx.phase = Phase::boxes;
            schedule(c, ready);
            return;
        }
        case Traversal::Step::leaf: {
            Cycle ready = mem->access({MemoryMap::triangle(ctx.trav.leaf_first()),
                                       uint32_t(sizeof(HwTriangle) * ctx.trav.leaf_count()), false, DataKind::triangle, t});
            ctx.phase = Phase::triangles;
            schedule(c, ready);
            return;
        }
        case Traversal::Step::done:
            finish_ray(c, t);
            return;
    }
}

Cycle TraversalUnit::stack_traffic(uint32_t c, int before, Cycle t, Cycle ready) {
    Context& ctx = m_contexts[c];
    const int after = ctx.trav.stack_size();
    const uint32_t cap = m_config.traversal.stack_entries, bytes = m_config.traversal.stack_entry_bytes;
    const uint64_t context = uint64_t(m_index) * m_contexts.size() + c;
    for (int i = before; i < after; ++i) {
        if (ctx.local_stack < cap) {
            ++ctx.local_stack;
            continue;
        }
        // Full on-chip stack: the oldest entry goes to memory (posted write).
        mem->access({MemoryMap::stack(context, ctx.spilled, bytes), bytes, true, DataKind::stack, t});
        ++ctx.spilled;
        ++m_spill_writes;
    }
    for (int i = after; i < before; ++i) {
        if (ctx.local_stack > 0) {
            --ctx.local_stack;
            continue;
        }
        // On-chip stack empty but entries in memory: read one back before going on.
        --ctx.spilled;
        ++m_spill_reads;
        ready = std::max(ready, mem->access({MemoryMap::stack(context, ctx.spilled, bytes), bytes, false, DataKind::stack, t}));
    }
    return ready;
}

void TraversalUnit::finish_ray(uint32_t c, Cycle t) {
    Context& ctx = m_contexts[c];
    // The hit record is written back (posted).
    mem->access({MemoryMap::hit(ctx.ray_id), sizeof(HitRecord), true, DataKind::hit, t});
    RayResult r{ctx.ray_id, ctx.trav.hit(), ctx.trav.work(), ctx.start, t, m_index, c};
    sink->ray_done(r);
    ++m_rays;
    m_finish = std::max(m_finish, t);
    ctx.active = false;
    if (--m_active == 0) m_busy_cycles += t - m_busy_since;  // a busy interval ends (may restart now)
    start_ray(c, t);
}

nlohmann::json TraversalUnit::stats_json(Cycle total_cycles) const {
    return {{"rays", m_rays},
            {"steps", m_steps},
            {"busy_cycles", m_busy_cycles},
            {"busy_fraction", total_cycles ? double(m_busy_cycles) / double(total_cycles) : 0.0},
            {"stack_spill_writes", m_spill_writes},
            {"stack_spill_reads", m_spill_reads},
            {"rejected_rays", m_rejected},
            {"quantum_syncs", m_syncs},
            {"finish_cycle", m_finish}};
}

}  // namespace rtsim
