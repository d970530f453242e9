#pragma once
// The interfaces the model's blocks talk through (SystemC interface method calls, bound with
// sc_port). Time is carried as cycle counts in the requests: a traversal unit runs ahead of
// SystemC time by at most a quantum (TLM-2.0 style temporal decoupling) and every block returns
// when its answer is ready, so no block needs a clock process (docs/architecture.md, rule 7).
#include <cstdint>

#include <systemc>

#include "traces/common/data_kind.h"
#include "traces/common/ray.h"

namespace rtsim {

using Cycle = uint64_t;

/// The memory level that served a read (its data came from there).
enum class ServedBy : uint8_t { l1 = 0, l2 = 1, dram = 2 };
constexpr int kServedByCount = 3;

/// Where a read's time went, filled by the levels it passes (for the issuer's cycle accounting,
/// docs/stats.md): which level served it and how long it waited for an MSHR at each cache.
struct AccessInfo {
    ServedBy level = ServedBy::l1;
    Cycle mshr_wait[2] = {0, 0};  ///< cycles waited for a free MSHR at the L1 [0] and the L2 [1]
};

struct MemRequest {
    uint64_t addr = 0;
    uint32_t bytes = 0;
    bool write = false;
    DataKind kind = DataKind::node;
    Cycle time = 0;              ///< cycle the request is issued
    AccessInfo* info = nullptr;  ///< optional: filled with where a read's time went
    /// A prefetch (a read nobody waits for) filling the cache of level `prefetch_into`; the levels
    /// above it pass it down, the levels below serve its miss as a read (counted as prefetch traffic).
    bool prefetch = false;
    ServedBy prefetch_into = ServedBy::l1;
};

/// Contract: returns the cycle the data is available (reads) or accepted (writes), >= req.time.
/// A prefetch at its target level returns req.time when it was taken (or was not needed: the line
/// is there) and, when no MSHR is free, the cycle one frees: the prefetcher retries then.
/// Requests from one issuer arrive in non-decreasing time; different issuers may be out of order
/// by up to a quantum.
class MemIf : public virtual sc_core::sc_interface {
public:
    virtual Cycle access(const MemRequest& req) = 0;
    /// Simulation speed only, no effect on the model's state: brings the host memory a read of
    /// `addr` will look at (a cache's tags of its set) into the host's cache ahead of the read.
    virtual void prefetch_host(uint64_t addr) const { (void)addr; }
};

/// Contract: `tests` tests in `issues` issues (the step-demand function's count at this
/// pipeline's width) issued at or after `time`; returns the cycle the last result is ready.
class PipeIf : public virtual sc_core::sc_interface {
public:
    virtual Cycle issue(Cycle time, uint32_t issues, uint32_t tests) = 0;
};

/// A ray handed to a traversal unit: its index in the trace and the ray itself.
struct RayJob {
    uint64_t id = 0;
    Ray ray;
    bool any_hit = false;
    Cycle not_before = 0;  ///< the ray may not start earlier (a frame barrier's release cycle)
    RayKind kind = RayKind::primary;  ///< what the ray is for (stats by kind)
};

/// Contract: hands out each ray of the workload exactly once; false when none are left now.
/// `unit` is the traversal unit asking (kAnyUnit: the ray buffer, which serves all units).
/// Frames (docs/model.md, "Frames"): a source may hold the next frame's rays back until every
/// ray of the current one has finished (ray_finished()); next_ray() is then false while
/// exhausted() is false, and `released()` is notified when the held rays may be taken.
class RaySourceIf : public virtual sc_core::sc_interface {
public:
    static constexpr uint32_t kAnyUnit = 0xFFFFFFFFu;
    virtual bool next_ray(uint32_t unit, RayJob* job) = 0;
    virtual uint64_t total_rays() const = 0;
    /// True when every ray of every frame has been handed out.
    virtual bool exhausted() const = 0;
    /// The frame whose rays are being handed out (0 without frames).
    virtual uint32_t frame() const { return 0; }
    /// Notified when a frame's rays are released, or rays held back may go; null for a source
    /// without frames.
    virtual const sc_core::sc_event* released() const { return nullptr; }
    /// Counts those releases: a unit that saw it change fills its idle slots again.
    virtual uint64_t releases() const { return frame(); }
    /// A ray the source handed out finished at `cycle` (its hit was written).
    virtual void ray_finished(Cycle cycle) {}
};

/// A finished ray: what the model computed, for the hit checker and statistics.
struct RayResult {
    uint64_t id = 0;
    Hit hit;
    WorkCounts work;
    Cycle start = 0;  ///< cycle the ray entered a context
    Cycle end = 0;    ///< cycle its hit was written
    uint32_t unit = 0;     ///< traversal unit that traced it
    uint32_t context = 0;  ///< ray context within the unit
    TraversalMode mode = TraversalMode::closest_hit;  ///< how it was traced (any-hit rays may be reordered)
};

/// Contract: called once per ray when it completes, in completion order.
class RaySinkIf : public virtual sc_core::sc_interface {
public:
    virtual void ray_done(const RayResult& result) = 0;
    /// A packet's rays finished together (traversal.model packet): results[i] is the ray traced
    /// from rays[i] in modes[i]. The default hands each result to ray_done().
    virtual void packet_done(const RayResult* results, const Ray* rays, const TraversalMode* modes, uint32_t n) {
        (void)rays, (void)modes;
        for (uint32_t i = 0; i < n; ++i) ray_done(results[i]);
    }
};

}  // namespace rtsim
