#include "rtl_model/traversal/traversal_unit.h"

#include <algorithm>

namespace rtsim {

TraversalUnit::TraversalUnit(sc_core::sc_module_name name, const SimConfig& config, const MemoryImage& image,
                             uint32_t index)
    : sc_core::sc_module(name), m_config(config), m_image(image), m_index(index), m_contexts(config.traversal.ray_contexts) {
    SC_THREAD(run);
}

void TraversalUnit::run() {
    m_treelet_mode = ray_buffer.size() > 0;
    Cycle now = 0;
    fill_idle_contexts(0);
    for (;;) {
        if (m_events.empty()) {
            // No ray in flight here. Without treelets that means dispatch is empty: done. With
            // treelets, rays may still be parked by other units: look again a little later.
            if (!m_treelet_mode || ray_buffer->done()) break;
            now += m_config.treelets.idle_poll_cycles;
            ++m_idle_polls;
            sync(now);
            fill_idle_contexts(now);
            continue;
        }
        Event e = m_events.top();
        m_events.pop();
        // The scheduler takes one step per issue_cycles.
        Cycle t = std::max(e.time, m_sched_free);
        m_sched_free = t + m_config.traversal.issue_cycles;
        now = t;
        sync(t);
        advance(e.context, t);
        if (m_treelet_mode && t >= m_next_fill) fill_idle_contexts(t);
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

void TraversalUnit::fill_idle_contexts(Cycle t) {
    for (uint32_t c = 0; c < m_contexts.size(); ++c)
        if (!m_contexts[c].active && !start_ray(c, t)) break;
    m_next_fill = t + m_config.treelets.idle_poll_cycles;
}

void TraversalUnit::activate(uint32_t c, Cycle t) {
    m_contexts[c].active = true;
    if (m_active++ == 0) m_busy_since = t;
}

bool TraversalUnit::start_ray(uint32_t c, Cycle t) {
    if (m_treelet_mode) return take_parked_ray(c, t);
    RayJob job;
    if (!rays->next_ray(m_index, &job)) return false;
    Context& ctx = m_contexts[c];
    ctx.ray.trav.begin(job.ray, job.any_hit ? TraversalMode::any_hit : TraversalMode::closest_hit);
    if (!ray_is_valid(job.ray)) ++m_rejected;
    ctx.ray.ray_id = job.id;
    ctx.ray.start = t;
    ctx.ray.local_stack = ctx.ray.spilled = 0;
    activate(c, t);
    // The ray record is read from memory before traversal starts.
    Cycle ready = mem->access({MemoryMap::ray(job.id), sizeof(RayRecord), false, DataKind::ray,
                               t + m_config.dispatch.latency});
    ctx.phase = Phase::fetch_ray;
    schedule(c, ready);
    return true;
}

bool TraversalUnit::take_parked_ray(uint32_t c, Cycle t) {
    Context& ctx = m_contexts[c];
    Cycle ready = t;
    if (!ray_buffer->take(m_index, t, &ctx.ray, &ctx.treelet, &ready)) return false;
    if (!ray_is_valid(ctx.ray.trav.ray()) && ctx.ray.trav.work().nodes == 0) ++m_rejected;
    ++m_takes;
    activate(c, t);
    ctx.phase = Phase::step;
    schedule(c, ready);
    return true;
}

void TraversalUnit::park_ray(uint32_t c, uint32_t treelet, Cycle t) {
    Context& ctx = m_contexts[c];
    ray_buffer->park(treelet, ctx.ray, t);
    ++m_parks;
    ctx.active = false;
    if (--m_active == 0) m_busy_cycles += t - m_busy_since;
    start_ray(c, t);
}

void TraversalUnit::advance(uint32_t c, Cycle t) {
    Context& ctx = m_contexts[c];
    Traversal& trav = ctx.ray.trav;
    ++m_steps;
    switch (ctx.phase) {
        case Phase::fetch_ray:
        case Phase::step:
            step(c, t);
            return;
        case Phase::boxes: {
            const uint32_t node = trav.node_index();
            Cycle ready = box->issue(t, 2);
            int before = trav.stack_size();
            trav.visit_node(m_image.nodes[node]);
            ctx.phase = Phase::step;
            schedule(c, stack_traffic(c, before, t, ready));
            return;
        }
        case Phase::triangles: {
            const uint32_t first = trav.leaf_first(), count = trav.leaf_count();
            Cycle ready = triangle->issue(t, count);
            uint32_t anyhit_before = trav.work().anyhit_calls;
            int before = trav.stack_size();
            trav.visit_leaf(&m_image.triangles[first]);
            uint32_t alpha_tests = trav.work().anyhit_calls - anyhit_before;
            if (alpha_tests) ready = anyhit->issue(ready, alpha_tests);
            ctx.phase = Phase::step;
            schedule(c, stack_traffic(c, before, t, ready));
            return;
        }
    }
}

void TraversalUnit::step(uint32_t c, Cycle t) {
    Context& ctx = m_contexts[c];
    Traversal& trav = ctx.ray.trav;
    switch (trav.step()) {
        case Traversal::Step::node: {
            const uint32_t node = trav.node_index();
            if (m_treelet_mode) {
                const uint32_t target = ray_buffer->treelet_of(node);
                if (target != ctx.treelet) return park_ray(c, target, t);  // leaves its treelet
            }
            Cycle ready = mem->access({MemoryMap::node(node), sizeof(HwNode), false, DataKind::node, t});
            ctx.phase = Phase::boxes;
            schedule(c, ready);
            return;
        }
        case Traversal::Step::leaf: {
            Cycle ready = mem->access({MemoryMap::triangle(trav.leaf_first()),
                                       uint32_t(sizeof(HwTriangle) * trav.leaf_count()), false, DataKind::triangle, t});
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
    RayState& ray = m_contexts[c].ray;
    const int after = ray.trav.stack_size();
    const uint32_t cap = m_config.traversal.stack_entries, bytes = m_config.traversal.stack_entry_bytes;
    // Spill slots belong to the context (reused ray after ray); with treelets they belong to the
    // ray (its id), since the ray moves between contexts and units through the ray buffer.
    const uint64_t owner = m_treelet_mode ? ray.ray_id : uint64_t(m_index) * m_contexts.size() + c;
    for (int i = before; i < after; ++i) {
        if (ray.local_stack < cap) {
            ++ray.local_stack;
            continue;
        }
        // Full on-chip stack: the oldest entry goes to memory (posted write).
        mem->access({MemoryMap::stack(owner, ray.spilled, bytes), bytes, true, DataKind::stack, t});
        ++ray.spilled;
        ++m_spill_writes;
    }
    for (int i = after; i < before; ++i) {
        if (ray.local_stack > 0) {
            --ray.local_stack;
            continue;
        }
        // On-chip stack empty but entries in memory: read one back before going on.
        --ray.spilled;
        ++m_spill_reads;
        ready = std::max(ready, mem->access({MemoryMap::stack(owner, ray.spilled, bytes), bytes, false, DataKind::stack, t}));
    }
    return ready;
}

void TraversalUnit::finish_ray(uint32_t c, Cycle t) {
    Context& ctx = m_contexts[c];
    // The hit record is written back (posted).
    mem->access({MemoryMap::hit(ctx.ray.ray_id), sizeof(HitRecord), true, DataKind::hit, t});
    RayResult r{ctx.ray.ray_id, ctx.ray.trav.hit(), ctx.ray.trav.work(), ctx.ray.start, t, m_index, c};
    sink->ray_done(r);
    if (m_treelet_mode) ray_buffer->finished(t);
    ++m_rays;
    m_finish = std::max(m_finish, t);
    ctx.active = false;
    if (--m_active == 0) m_busy_cycles += t - m_busy_since;  // a busy interval ends (may restart now)
    start_ray(c, t);
}

nlohmann::json TraversalUnit::stats_json(Cycle total_cycles) const {
    nlohmann::json j = {{"rays", m_rays},
                        {"steps", m_steps},
                        {"busy_cycles", m_busy_cycles},
                        {"busy_fraction", total_cycles ? double(m_busy_cycles) / double(total_cycles) : 0.0},
                        {"stack_spill_writes", m_spill_writes},
                        {"stack_spill_reads", m_spill_reads},
                        {"rejected_rays", m_rejected},
                        {"quantum_syncs", m_syncs},
                        {"finish_cycle", m_finish}};
    if (m_treelet_mode) {
        j["rays_taken"] = m_takes;
        j["rays_parked"] = m_parks;
        j["idle_polls"] = m_idle_polls;
    }
    return j;
}

}  // namespace rtsim
