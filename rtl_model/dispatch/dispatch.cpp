#include "rtl_model/dispatch/dispatch.h"

#include <algorithm>

namespace rtsim {

RayDealer::RayDealer(const DispatchConfig& config, uint32_t units, RayStream& stream)
    : m_config(config), m_stream(stream), m_sorter(config), m_queues(std::max(1u, units)) {}

bool RayDealer::next_ray(uint32_t unit, RayJob* job) {
    bool ok = m_config.policy == DispatchPolicy::on_demand ? next_on_demand(job) : next_interleaved(unit, job);
    m_dispatched += ok;
    return ok;
}

bool RayDealer::next_on_demand(RayJob* job) {
    if (m_next == m_buffer.size()) {
        m_buffer.clear();
        m_next = 0;
        if (m_stream_done || m_stream.read_chunk(m_config.chunk_rays, &m_buffer) == 0) {
            m_stream_done = true;
            return next_segment() && next_on_demand(job);
        }
        sort_chunk(m_buffer);
        ++m_chunks;
    }
    *job = m_buffer[m_next++];
    return true;
}

bool RayDealer::deal_chunk() {
    // Deal the next chunk to the units in turn, block_rays at a time.
    std::vector<RayJob> chunk;
    if (m_stream_done || m_stream.read_chunk(m_config.chunk_rays, &chunk) == 0) {
        m_stream_done = true;
        return false;
    }
    sort_chunk(chunk);
    ++m_chunks;
    for (size_t i = 0; i < chunk.size(); i += m_config.block_rays) {
        size_t end = std::min(chunk.size(), i + m_config.block_rays);
        m_queues[m_deal_unit].insert(m_queues[m_deal_unit].end(), chunk.begin() + i, chunk.begin() + end);
        m_deal_unit = (m_deal_unit + 1) % m_queues.size();
    }
    return true;
}

bool RayDealer::next_segment() {
    if (!m_stream_done) return false;
    for (const auto& q : m_queues)
        if (!q.empty()) return false;
    if (!m_stream.next_segment()) return false;
    m_stream_done = false;
    return true;
}

bool RayDealer::next_interleaved(uint32_t unit, RayJob* job) {
    if (unit == kAnyUnit) unit = m_any_unit++ % m_queues.size();
    unit %= m_queues.size();
    if (m_queues[unit].empty()) deal_chunk();
    if (!m_queues[unit].empty()) {
        *job = m_queues[unit].front();
        m_queues[unit].pop_front();
    } else {
        // Nothing left for this unit: steal the last ray of the longest queue.
        auto longest = std::max_element(m_queues.begin(), m_queues.end(),
                                        [](const auto& a, const auto& b) { return a.size() < b.size(); });
        if (longest->empty()) return next_segment() && next_interleaved(unit, job);
        *job = longest->back();
        longest->pop_back();
        ++m_steals;
    }
    // The last ray of a segment is out: the next segment, if any, is read on the next request
    // (so exhausted() is true only at the stream's end).
    if (m_stream_done) next_segment();
    return true;
}

bool RayDealer::exhausted() const {
    if (!m_stream_done || m_next < m_buffer.size()) return false;
    return std::all_of(m_queues.begin(), m_queues.end(), [](const auto& q) { return q.empty(); });
}

const StatBlock& dispatch_stats() {
    static const StatBlock block{
        "model.dispatch",
        {
            {"rays", "rays", "rays handed to ray contexts"},
            {"chunks", "chunks", "chunks read from the trace file"},
            {"chunk_rays", "rays", "the configured chunk size (`dispatch.chunk_rays`)"},
            {"policy", "", "`interleaved` (rays dealt to units in turn) or `on_demand` (`dispatch.policy`)"},
            {"steals", "rays", "rays an idle unit took from another unit's queue (interleaved, at the end of the trace)"},
            {"sort", "", "with `dispatch.sort` only: the sorting stage's key", false, true},
            {"sorted_rays", "rays", "with `dispatch.sort` only: rays through the sorting stage", false, true},
            {"sort_ready_cycle", "cycle", "with `dispatch.sort` only: when its last window was ready (rays may not start earlier)", false, true},
        }};
    return block;
}

nlohmann::json RayDealer::stats_json() const {
    nlohmann::json j;
    StatsWriter w(dispatch_stats(), j);
    w.set("rays", m_dispatched)
        .set("chunks", m_chunks)
        .set("chunk_rays", m_config.chunk_rays)
        .set("policy", kDispatchPolicyChoices.name(m_config.policy))
        .set("steals", m_steals);
    if (m_config.sort != RaySort::none)
        w.set("sort", kRaySortChoices.name(m_config.sort))
            .set("sorted_rays", m_sorter.sorted())
            .set("sort_ready_cycle", m_sorter.ready());
    w.done();
    return j;
}

Dispatch::Dispatch(sc_core::sc_module_name name, const DispatchConfig& config, uint32_t units, RayStream& stream)
    : sc_core::sc_module(name), RayDealer(config, units, stream), m_frame_rays{stream.total_rays()} {}

void Dispatch::set_frames(std::vector<uint64_t> frame_rays, FrameEnd on_end, FrameBegin on_begin) {
    m_frame_rays = std::move(frame_rays);
    m_on_end = std::move(on_end);
    m_on_begin = std::move(on_begin);
    // Leading empty frames end at cycle 0 (no ray of theirs will finish to end them), each
    // through the barrier when one is set first (a moving scene's builds before the next frame).
    Cycle release = 0;
    for (m_frame = 0;; ++m_frame) {
        stream().begin_frame(m_frame);
        if (m_on_begin) m_on_begin(m_frame);
        if (m_frame_rays[m_frame] != 0 || m_frame + 1 >= m_frame_rays.size()) break;
        if (m_barrier) release = std::max(release, m_barrier(m_frame, release));
        if (m_on_end) m_on_end(m_frame, release);
    }
    m_release = std::max(m_release, release);
}

bool Dispatch::next_ray(uint32_t unit, RayJob* job) {
    if (m_gate) return next_gated(unit, job);
    if (!RayDealer::next_ray(unit, job)) return false;
    job->not_before = std::max(job->not_before, m_release);  // sorted rays wait for their window
    ++m_handed;
    return true;
}

bool Dispatch::next_gated(uint32_t unit, RayJob* job) {
    // Released rays first (their parents are shaded), then the stream, holding back each ray
    // whose parent is not; the stream is read ahead at most kMaxHeld held rays.
    constexpr uint64_t kMaxHeld = 1u << 16;
    Cycle not_before = 0;
    auto hand = [&](const RayJob& ray) {
        *job = ray;
        job->not_before = std::max({job->not_before, m_release, not_before});
        ++m_handed;
        return true;
    };
    auto hold = [&](const RayJob& ray) {
        m_waiting[m_waits_for(ray.id)].push_back(ray);
        ++m_waiting_rays;
    };
    while (!m_ready.empty()) {
        const RayJob ray = m_ready.front();
        m_ready.pop_front();
        if (m_gate(ray.id, &not_before)) return hand(ray);
        hold(ray);  // released for a ray that was not the one it waits for: wait again
    }
    RayJob next;
    while (m_waiting_rays < kMaxHeld && RayDealer::next_ray(unit, &next)) {
        if (m_gate(next.id, &not_before)) return hand(next);
        hold(next);
    }
    return false;
}

void Dispatch::release(const std::vector<uint64_t>& ids) {
    for (uint64_t id : ids) {
        auto it = m_waiting.find(id);
        if (it == m_waiting.end()) continue;
        m_ready.insert(m_ready.end(), it->second.begin(), it->second.end());
        m_waiting_rays -= it->second.size();
        m_waiting.erase(it);
    }
    ++m_releases;
    m_released.notify(sc_core::SC_ZERO_TIME);
}

bool Dispatch::exhausted() const {
    return m_frame + 1 >= m_frame_rays.size() && RayDealer::exhausted() && m_waiting_rays == 0 && m_ready.empty();
}

void Dispatch::ray_finished(Cycle cycle) {
    ++m_finished_total;
    m_frame_end = std::max(m_frame_end, cycle);
    if (++m_finished < m_frame_rays[m_frame]) return;
    // The frame's last ray is done: the next frame (skipping empty ones) starts at its cycle,
    // or when the barrier (the shading of a wavefront) releases it.
    do {
        if (m_barrier) m_frame_end = std::max(m_frame_end, m_barrier(m_frame, m_frame_end));
        if (m_on_end) m_on_end(m_frame, m_frame_end);
        if (m_frame + 1 >= m_frame_rays.size()) return;
        ++m_frame;
        m_finished = 0;
        stream().begin_frame(m_frame);
        if (m_on_begin) m_on_begin(m_frame);
    } while (m_frame_rays[m_frame] == 0);
    m_release = m_frame_end;
    resume_stream();
    ++m_releases;
    m_released.notify(sc_core::SC_ZERO_TIME);
}

RTSIM_REGISTER_STAT_BLOCK(dispatch_stats)

}  // namespace rtsim
