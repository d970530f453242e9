#pragma once
// Dispatch: hands rays to the traversal units, refilling its buffer one chunk at a time from a
// RayStream (the harness streams the trace file; memory stays bounded, rule 8).
//
// interleaved (default): each chunk is dealt to per-unit queues in turn, block_rays consecutive
// rays at a time; a unit whose queue is empty steals from the back of the longest queue. The
// assignment is the hardware's policy and does not depend on how far units run ahead of each
// other (quantum_cycles), so the approx and detailed levels give rays to the same units.
// on_demand: the next ray in trace order goes to whichever unit asks first. With dispatch.sort,
// each chunk passes a sorting stage first (ray_sort.h) and "trace order" is its sorted order. With temporal
// decoupling a unit running ahead then takes runs of neighbouring rays, which flatters its L1.
#include <cstdint>
#include <deque>
#include <functional>
#include <unordered_map>
#include <vector>

#include <nlohmann/json.hpp>
#include <systemc>

#include "rtl_model/common/interfaces.h"
#include "rtl_model/common/stats.h"
#include "rtl_model/dispatch/dispatch_config.h"
#include "rtl_model/dispatch/ray_sort.h"

namespace rtsim {

/// The stats every dispatch writes (model.dispatch; the analytic level's RayDealer too).
const StatBlock& dispatch_stats();

/// Where rays come from (implemented by the harness over the trace file).
class RayStream {
public:
    virtual ~RayStream() = default;
    /// Appends up to `max` rays in trace order to `out`; returns how many (0 at the end, or at
    /// the end of the current frame: see Dispatch::set_frames).
    virtual size_t read_chunk(size_t max, std::vector<RayJob>* out) = 0;
    virtual uint64_t total_rays() const = 0;
    /// Frames: the stream goes on with frame `f`'s rays (its reads end at that frame's last ray).
    virtual void begin_frame(uint32_t f) {}
    /// Segments (a sampled run's clusters, sim/sampling/sampling.h): read_chunk returns 0 at a
    /// segment's end; the dealer calls this once it has handed out every ray read so far, and
    /// reads on if it returns true. So a segment's first read (and what the stream does then)
    /// comes after the last ray of the previous segment has entered a context.
    virtual bool next_segment() { return false; }
};

/// The dealing policy itself, plain C++: the Dispatch block wraps it for the SystemC model, and
/// the analytic level (which has no SystemC time, and may run after a simulation) uses it
/// directly, so both give rays to the same units.
class RayDealer : public RaySourceIf {
public:
    RayDealer(const DispatchConfig& config, uint32_t units, RayStream& stream);

    bool next_ray(uint32_t unit, RayJob* job) override;
    uint64_t total_rays() const override { return m_stream.total_rays(); }
    /// The stream is at its end and every ray read from it was handed out.
    bool exhausted() const override;
    uint64_t dispatched() const { return m_dispatched; }
    nlohmann::json stats_json() const;

protected:
    /// The stream has more rays again (its next frame): deal on.
    void resume_stream() { m_stream_done = false; }
    RayStream& stream() { return m_stream; }

private:
    bool next_on_demand(RayJob* job);
    bool next_interleaved(uint32_t unit, RayJob* job);
    bool deal_chunk();
    /// Every ray read so far is handed out and the stream is at a segment's end: go on with the
    /// next segment (false at the stream's end).
    bool next_segment();

    /// A chunk just read from the stream goes through the sorting stage (dispatch.sort).
    void sort_chunk(std::vector<RayJob>& chunk) {
        if (m_config.sort != RaySort::none) m_sorter.sort(chunk);
    }

    DispatchConfig m_config;
    RayStream& m_stream;
    RaySorter m_sorter;
    std::vector<RayJob> m_buffer;  ///< on_demand: the current chunk
    size_t m_next = 0;
    std::vector<std::deque<RayJob>> m_queues;  ///< interleaved: per-unit queues
    uint32_t m_deal_unit = 0;                   ///< unit the next block goes to
    uint32_t m_any_unit = 0;                    ///< rotor for kAnyUnit requests
    bool m_stream_done = false;
    uint64_t m_dispatched = 0, m_chunks = 0, m_steals = 0;
};

/// The dispatch block. With frames (docs/model.md, "Frames") it is also the frame barrier: it
/// hands out frame f + 1's rays only once every ray of frame f has finished, at the cycle the
/// last one finished (RayJob::not_before), after calling the frame hooks (the harness records
/// the frame's figures and binds the structure's next frame).
class Dispatch : public sc_core::sc_module, public RayDealer {
public:
    /// end: frame f's last ray finished at `cycle`; begin: frame f is about to be handed out.
    using FrameEnd = std::function<void(uint32_t f, Cycle cycle)>;
    using FrameBegin = std::function<void(uint32_t f)>;

    Dispatch(sc_core::sc_module_name name, const DispatchConfig& config, uint32_t units, RayStream& stream);

    /// Rays per frame (summing to the stream's rays); without a call, one frame of every ray.
    void set_frames(std::vector<uint64_t> frame_rays, FrameEnd on_end, FrameBegin on_begin);

    /// A barrier's release: frame (or wavefront) f's last ray finished at `cycle`; returns the
    /// cycle the next one's rays may start (the shading block's end of shading it).
    using Barrier = std::function<Cycle(uint32_t f, Cycle cycle)>;
    void set_barrier(Barrier barrier) { m_barrier = std::move(barrier); }
    /// No ray starts before `cycle` (ray generation's end).
    void hold_until(Cycle cycle) { m_release = std::max(m_release, cycle); }
    /// A ray may go only when gate(id, &not_before) is true (the in-flight frame loop: its
    /// parent is shaded); a ray held back waits under the ray `waits_for(id)` names, until
    /// release() names that one. Rays are read from the stream in the dealer's order, which is
    /// not parents first (each unit deals from its own chunk), so held rays are found by what
    /// they wait for, never by scanning them in order.
    using Gate = std::function<bool(uint64_t id, Cycle* not_before)>;
    using WaitsFor = std::function<uint64_t(uint64_t id)>;
    void set_gate(Gate gate, WaitsFor waits_for) {
        m_gate = std::move(gate);
        m_waits_for = std::move(waits_for);
    }
    /// The rays held for `ids` may go now: waiting units ask again.
    void release(const std::vector<uint64_t>& ids);
    /// Rays handed to units and not yet finished.
    uint64_t in_flight() const { return m_handed - m_finished_total; }

    bool next_ray(uint32_t unit, RayJob* job) override;
    bool exhausted() const override;
    uint32_t frame() const override { return m_frame; }
    const sc_core::sc_event* released() const override { return &m_released; }
    uint64_t releases() const override { return m_releases; }
    void ray_finished(Cycle cycle) override;

private:
    bool next_gated(uint32_t unit, RayJob* job);

    Barrier m_barrier;
    Gate m_gate;
    WaitsFor m_waits_for;
    /// Gated rays read from the stream but not yet allowed, by the ray each waits for.
    std::unordered_map<uint64_t, std::vector<RayJob>> m_waiting;
    uint64_t m_waiting_rays = 0;
    std::deque<RayJob> m_ready;  ///< released rays, handed out first
    uint64_t m_releases = 0;     ///< frames released plus release() calls (RaySourceIf::releases)
    uint64_t m_handed = 0, m_finished_total = 0;
    std::vector<uint64_t> m_frame_rays;
    FrameEnd m_on_end;
    FrameBegin m_on_begin;
    uint32_t m_frame = 0;
    uint64_t m_finished = 0;   ///< rays of the current frame finished
    Cycle m_frame_end = 0;     ///< latest finish among them
    Cycle m_release = 0;       ///< cycle the current frame's rays may start
    sc_core::sc_event m_released;
};

}  // namespace rtsim
