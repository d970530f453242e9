#include "rtl_model/traversal/simt/simt_profile.h"

#include <array>
#include <memory>

#include "rtl_model/common/interfaces.h"
#include "rtl_model/traversal/simt/coalescer.h"
#include "rtl_model/traversal/simt/cooperation.h"
#include "rtl_model/traversal/simt/simt_config.h"
#include "rtl_model/traversal/simt/simt_unit.h"
#include "rtl_model/traversal/traversal_config.h"
#include "traces/accel/accel.h"

namespace rtsim {

namespace {

constexpr uint32_t kClasses = kOpKindCount + 1;

struct Lane {
    std::unique_ptr<Stepper> stepper;
    bool has_ray = false;
    CooperativeWalk walk;  ///< cooperative lanes: the ray's walk, stepped ahead (cooperation.h)
};

/// The warps of the whole machine and the rays they take, in turn.
class FunctionalWarps {
public:
    FunctionalWarps(const Accel& accel, const StepOptions& step, const TraversalConfig& t,
                    const std::vector<std::vector<RayJob>>& rays_by_unit, uint32_t line_bytes)
        : m_simt(t.kind_config<SimtConfig>()),
          m_rays(rays_by_unit),
          m_next(rays_by_unit.size(), 0),
          m_warps_per_unit(t.groups()),
          m_lanes(rays_by_unit.size() * t.groups() * m_simt.lanes),
          m_last_class(rays_by_unit.size() * t.groups(), 0),
          m_coalescer(line_bytes) {
        for (Lane& l : m_lanes) l.stepper = accel.make_stepper(step);
        for (const auto& r : rays_by_unit) m_p.rays += double(r.size());
    }

    GroupProfile run() {
        const size_t warps = m_last_class.size();
        for (bool any = true; any;) {
            any = false;
            for (size_t w = 0; w < warps; ++w) any = step(w) || any;
        }
        m_p.lane_requests = double(m_coalescer.lane_requests());
        return m_p;
    }

private:
    Lane& lane(size_t w, uint32_t i) { return m_lanes[w * m_simt.lanes + i]; }

    /// Retires finished lanes and refills them as simt_refill lets; true when rays were taken.
    bool refill(size_t w) {
        bool any_ray = false;
        for (uint32_t i = 0; i < m_simt.lanes; ++i) {
            Lane& l = lane(w, i);
            if (l.has_ray && (m_simt.cooperative ? l.walk.done() : l.stepper->plan().done)) {
                for (size_t f = 0; f < m_p.work.size(); ++f) m_p.work[f] += l.stepper->work().*kWorkFields[f].member;
                l.has_ray = false;
            }
            any_ray = any_ray || l.has_ray;
        }
        if (m_simt.refill == SimtRefill::warp && any_ray) return false;
        uint32_t taken = 0;
        const size_t unit = w / m_warps_per_unit;
        for (uint32_t i = 0; i < m_simt.lanes && m_next[unit] < m_rays[unit].size(); ++i) {
            Lane& l = lane(w, i);
            if (l.has_ray) continue;
            const RayJob& job = m_rays[unit][m_next[unit]++];
            l.stepper->begin(job.ray, job.any_hit ? TraversalMode::any_hit : TraversalMode::closest_hit);
            l.has_ray = true;
            if (m_simt.cooperative) {
                StackSplit unused;
                l.walk.record(*l.stepper, unused, nullptr);
            }
            ++taken;
        }
        if (taken) {  // a warp step of its own fetches the new rays' records (coalesced)
            m_p.group_steps += 1, m_p.scheduler_steps += 1;
            m_p.lane_slots += m_simt.lanes, m_p.active_lanes += taken;
        }
        return taken > 0;
    }

    /// One warp step of warp w (or its refill); false when it has nothing to do.
    uint32_t lane_class(size_t w, uint32_t i) {
        Lane& l = lane(w, i);
        return m_simt.cooperative ? l.walk.next_class(kOpKindCount) : SimtUnit::step_class(l.stepper->plan());
    }

    bool step(size_t w) {
        if (m_simt.cooperative)
            for (uint32_t i = 0; i < m_simt.lanes; ++i)
                if (lane(w, i).has_ray) lane(w, i).walk.release();
        if (refill(w)) return true;
        std::array<uint32_t, kClasses> want{};
        bool any = false;
        for (uint32_t i = 0; i < m_simt.lanes; ++i)
            if (lane(w, i).has_ray) ++want[lane_class(w, i)], any = true;
        if (!any) return false;
        uint32_t cls = m_last_class[w];
        if (!(m_simt.policy == SimtPolicy::while_while && want[cls]))
            for (uint32_t k = 1; k <= kClasses; ++k)
                if (want[(cls + k) % kClasses]) {
                    cls = (cls + k) % kClasses;
                    break;
                }
        m_last_class[w] = cls;
        uint32_t active = 0;
        for (uint32_t i = 0; i < m_simt.lanes; ++i) {
            Lane& l = lane(w, i);
            if (!l.has_ray || lane_class(w, i) != cls) continue;
            if (m_simt.cooperative) take(l, cls);
            else run_step(*l.stepper);
            ++active;
        }
        if (m_simt.cooperative) active += lend_idle_lanes(w, cls);
        m_p.requests += m_coalescer.issue([](uint64_t, uint32_t, DataKind) {});
        m_p.group_steps += 1, m_p.scheduler_steps += 2;  // the step and its operations
        if (cls < kOpKindCount) m_p.kind_steps[cls] += 1;
        m_p.lane_slots += m_simt.lanes, m_p.active_lanes += active;
        return true;
    }

    void run_step(Stepper& s) {
        const StepPlan& plan = s.plan();
        for (uint32_t f = 0; f < plan.fetch_count; ++f) m_coalescer.add(plan.fetch[f].addr, plan.fetch[f].bytes, plan.fetch[f].kind);
        s.execute();
    }

    void take(Lane& l, uint32_t cls) {
        StepDemand unused;
        l.walk.take(
            cls, unused, [&](const Fetch& f) { m_coalescer.add(f.addr, f.bytes, f.kind); }, [](const Fetch&) {});
    }

    /// Cooperative lanes, as the unit lends them (simt_unit.h): the helper steps run.
    uint32_t lend_idle_lanes(size_t w, uint32_t cls) {
        uint32_t helpers = 0;
        for (uint32_t i = 0; i < m_simt.lanes; ++i) {
            if (lane(w, i).has_ray) continue;
            const uint32_t best = pick_helped_lane(
                0, m_simt.lanes, [&](uint32_t l) { return lane(w, l).has_ray ? lane(w, l).walk.ready(cls) : 0; },
                [](uint32_t) { return true; });
            if (best == m_simt.lanes) break;
            take(lane(w, best), cls);
            ++helpers;
        }
        return helpers;
    }

    const SimtConfig& m_simt;
    const std::vector<std::vector<RayJob>>& m_rays;
    std::vector<size_t> m_next;  ///< per unit: its next ray
    size_t m_warps_per_unit;
    std::vector<Lane> m_lanes;
    std::vector<uint32_t> m_last_class;
    LineCoalescer m_coalescer;
    GroupProfile m_p;
};

}  // namespace

GroupProfile simt_group_profile(const Accel& accel, const StepOptions& step, const TraversalConfig& traversal,
                                const std::vector<std::vector<RayJob>>& rays_by_unit, uint32_t line_bytes) {
    GroupProfile p = FunctionalWarps(accel, step, traversal, rays_by_unit, line_bytes).run();
    p.single_work = p.work;  // each lane walks its ray alone: the work is the single ray's
    return p;
}

}  // namespace rtsim
