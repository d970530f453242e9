#include "rtl_model/traversal/simt/simt_profile.h"

#include <algorithm>
#include <array>
#include <deque>
#include <memory>

#include "rtl_model/common/interfaces.h"
#include "rtl_model/traversal/simt/coalescer.h"
#include "rtl_model/traversal/simt/cooperation.h"
#include "rtl_model/traversal/simt/simt_config.h"
#include "rtl_model/traversal/simt/simt_unit.h"
#include "rtl_model/traversal/traversal_config.h"
#include "traces/accel/accel.h"
#include "traces/accel/locality.h"

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
                    const std::vector<std::vector<RayJob>>& rays_by_unit, const GroupSetup& setup)
        : m_simt(t.kind_config<SimtConfig>()),
          m_rays(rays_by_unit),
          m_next(rays_by_unit.size(), 0),
          m_warps_per_unit(t.groups()),
          m_lanes(rays_by_unit.size() * t.groups() * m_simt.lanes),
          m_last_class(rays_by_unit.size() * t.groups(), 0),
          m_coalescer(setup.line_bytes),
          m_setup(setup),
          m_accel(accel),
          m_step(step),
          // As the unit: with treelet queues a lane's ray may leave mid-walk, so no walk ahead.
          m_cooperative(m_simt.cooperative && !setup.treelets),
          m_wait(m_last_class.size(), 0) {
        while ((1u << m_line_shift) < setup.line_bytes) ++m_line_shift;
        for (const auto& r : rays_by_unit) m_p.rays += double(r.size());
        if (!setup.treelets) {
            for (Lane& l : m_lanes) l.stepper = accel.make_stepper(step);
            return;
        }
        m_queues.resize(setup.treelets->treelets.size());
        m_warp_treelet.assign(m_last_class.size(), -1);
        // The ray buffer admits from dispatch for the whole machine: the units' rays in the
        // order they were dealt.
        for (size_t i = 0, any = 1; any; ++i) {
            any = 0;
            for (const auto& r : rays_by_unit)
                if (i < r.size()) m_admission.push_back(&r[i]), any = 1;
        }
    }

    GroupProfile run() {
        const size_t warps = m_last_class.size();
        // The rounds' windows (GroupWindow): without treelet queues, whose warps re-form.
        const bool phases = !m_setup.treelets;
        double window_rounds = 1;
        if (phases) m_p.phases.emplace_back();
        for (bool any = true; any;) {
            any = false;
            const double steps = m_p.group_steps, lanes = m_p.active_lanes;
            uint32_t busy = 0;  // warps stepping or waiting for their last step's line
            for (size_t w = 0; w < warps; ++w) {
                if (m_wait[w]) {
                    --m_wait[w], ++busy, any = true;
                } else if (step(w)) {
                    ++busy, any = true;
                }
            }
            if (!any || !phases) continue;
            m_p.phases.back().group_steps += m_p.group_steps - steps;
            m_p.phases.back().active_lanes += m_p.active_lanes - lanes;
            m_p.phases.back().groups += busy;
            GroupWindow::end_round(m_p.phases, &window_rounds);
        }
        if (!m_p.phases.empty() && m_p.phases.back().rounds == 0) m_p.phases.pop_back();
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
            if (l.has_ray && (m_cooperative ? l.walk.done() : l.stepper->plan().done)) {
                for (size_t f = 0; f < m_p.work.size(); ++f) m_p.work[f] += l.stepper->work().*kWorkFields[f].member;
                l.has_ray = false;
                if (m_setup.treelets) --m_in_machine, m_free.push_back(std::move(l.stepper));
            }
            any_ray = any_ray || l.has_ray;
        }
        if (m_simt.refill == SimtRefill::warp && any_ray) return false;
        const uint32_t taken = m_setup.treelets ? take_from_queues(w, any_ray) : take_dealt(w);
        if (taken) {  // a warp step of its own fetches the new rays' records (coalesced) or states
            m_p.group_steps += 1, m_p.scheduler_steps += 1;
            if (m_setup.treelets) m_p.buffer_steps += 1;
            m_p.lane_slots += m_simt.lanes, m_p.active_lanes += taken, m_p.occupied_lanes += occupied(w);
        }
        return taken > 0;
    }

    /// One warp step of warp w (or its refill); false when it has nothing to do.
    uint32_t lane_class(size_t w, uint32_t i) {
        Lane& l = lane(w, i);
        return m_cooperative ? l.walk.next_class(kOpKindCount) : SimtUnit::step_class(l.stepper->plan());
    }

    bool step(size_t w) {
        if (m_cooperative)
            for (uint32_t i = 0; i < m_simt.lanes; ++i)
                if (lane(w, i).has_ray) lane(w, i).walk.release();
        if (refill(w)) return true;
        // Lanes whose next step is in another treelet park there; a warp they all left forms
        // again from a queue (simt_unit.cpp, park_leavers).
        if (m_setup.treelets && park_leavers(w) && refill(w)) return true;
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
            if (m_cooperative) take(l, cls);
            else run_step(*l.stepper);
            ++active;
        }
        if (m_cooperative) active += lend_idle_lanes(w, cls);
        // Rounds as time (GroupSetup::line_wait): the warp waits for its step's slowest line;
        // only where the rounds' windows are kept (treelet queues keep none).
        LineWait slowest;
        bool read = false;
        const uint32_t unit = uint32_t(w / m_warps_per_unit);
        const bool waits = m_setup.line_wait && !m_setup.treelets;
        m_p.requests += m_coalescer.issue([&](uint64_t addr, uint32_t, DataKind) {
            if (!waits) return;
            const LineWait l = m_setup.line_wait(unit, addr >> m_line_shift);
            if (!read || l.level > slowest.level) slowest = l;
            read = true;
        });
        m_wait[w] = slowest.rounds;
        if (read && !m_p.phases.empty()) m_p.phases.back().served[slowest.level] += 1;
        m_p.group_steps += 1, m_p.scheduler_steps += 2;  // the step and its operations
        if (cls < kOpKindCount) m_p.kind_steps[cls] += 1;
        m_p.lane_slots += m_simt.lanes, m_p.active_lanes += active, m_p.occupied_lanes += occupied(w);
        return true;
    }

    uint32_t occupied(size_t w) {
        uint32_t n = 0;
        for (uint32_t i = 0; i < m_simt.lanes; ++i) n += lane(w, i).has_ray;
        return n;
    }

    /// Idle lanes take the rays dispatch dealt the warp's unit, in order.
    uint32_t take_dealt(size_t w) {
        uint32_t taken = 0;
        const size_t unit = w / m_warps_per_unit;
        for (uint32_t i = 0; i < m_simt.lanes && m_next[unit] < m_rays[unit].size(); ++i) {
            Lane& l = lane(w, i);
            if (l.has_ray) continue;
            const RayJob& job = m_rays[unit][m_next[unit]++];
            l.stepper->begin(job.ray, job.any_hit ? TraversalMode::any_hit : TraversalMode::closest_hit);
            l.has_ray = true;
            if (m_cooperative) {
                StackSplit unused;
                l.walk.record(*l.stepper, unused, nullptr);
            }
            ++taken;
        }
        return taken;
    }

    /// Treelet scheduling (simt_unit.cpp, take_lane): idle lanes take rays from the warp's
    /// treelet queue; a warp holding no ray may move to the largest queue first.
    uint32_t take_from_queues(size_t w, bool any_ray) {
        admit();
        uint32_t taken = 0;
        for (uint32_t i = 0; i < m_simt.lanes; ++i) {
            Lane& l = lane(w, i);
            if (l.has_ray) continue;
            int64_t& current = m_warp_treelet[w];
            if (current < 0 || m_queues[size_t(current)].empty()) {
                if (any_ray || taken) break;
                current = largest_queue();
                if (current < 0) break;
            }
            l.stepper = std::move(m_queues[size_t(current)].front());
            m_queues[size_t(current)].pop_front();
            --m_waiting;
            l.has_ray = true;
            ++taken;
        }
        return taken;
    }

    /// New rays into the queue of their first step's treelet, as the ray buffer admits them.
    void admit() {
        const uint64_t reserve = m_setup.capacity > 1 ? 1 : 0;
        while (m_admitted < m_admission.size() && m_in_machine < m_setup.admit_limit &&
               (m_setup.may_overflow || m_waiting + reserve < m_setup.capacity)) {
            const RayJob& job = *m_admission[m_admitted++];
            std::unique_ptr<Stepper> s;
            if (m_free.empty()) {
                s = m_accel.make_stepper(m_step);
            } else {
                s = std::move(m_free.back());
                m_free.pop_back();
            }
            s->begin(job.ray, job.any_hit ? TraversalMode::any_hit : TraversalMode::closest_hit);
            const uint32_t first = s->plan().locality;
            park(std::move(s), first == kNoLocality ? m_setup.treelets->root_group : m_setup.treelets->group_of[first]);
            ++m_in_machine;
        }
    }

    void park(std::unique_ptr<Stepper> s, uint32_t treelet) {
        m_queues[treelet].push_back(std::move(s));
        ++m_waiting;
    }

    /// Parks the lanes whose next step is outside the warp's treelet; true when none is left.
    bool park_leavers(size_t w) {
        bool any_ray = false;
        for (uint32_t i = 0; i < m_simt.lanes; ++i) {
            Lane& l = lane(w, i);
            if (!l.has_ray) continue;
            const StepPlan& plan = l.stepper->plan();
            const uint32_t target =
                plan.done || plan.locality == kNoLocality ? uint32_t(m_warp_treelet[w]) : m_setup.treelets->group_of[plan.locality];
            if (int64_t(target) == m_warp_treelet[w]) {
                any_ray = true;
                continue;
            }
            park(std::move(l.stepper), target);
            l.has_ray = false;
        }
        return !any_ray;
    }

    int64_t largest_queue() const {
        if (m_waiting == 0) return -1;  // no ray waits: no queue to scan (idle warps ask every round)
        int64_t best = -1;
        for (size_t k = 0; k < m_queues.size(); ++k)
            if (!m_queues[k].empty() && (best < 0 || m_queues[k].size() > m_queues[size_t(best)].size())) best = int64_t(k);
        return best;
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
    const GroupSetup& m_setup;
    const Accel& m_accel;
    const StepOptions& m_step;
    bool m_cooperative;
    std::vector<uint32_t> m_wait;  ///< per warp: rounds it still waits (GroupSetup::line_wait)
    uint32_t m_line_shift = 0;
    // Treelet scheduling: the ray buffer's queues, the rays it admits and the warps' treelets.
    std::vector<std::deque<std::unique_ptr<Stepper>>> m_queues;
    std::vector<const RayJob*> m_admission;
    size_t m_admitted = 0;
    uint64_t m_in_machine = 0, m_waiting = 0;
    std::vector<int64_t> m_warp_treelet;
    std::vector<std::unique_ptr<Stepper>> m_free;  ///< steppers of finished rays, reused
    GroupProfile m_p;
};

}  // namespace

GroupProfile simt_group_profile(const Accel& accel, const StepOptions& step, const TraversalConfig& traversal,
                                const std::vector<std::vector<RayJob>>& rays_by_unit, const GroupSetup& setup) {
    GroupProfile p = FunctionalWarps(accel, step, traversal, rays_by_unit, setup).run();
    p.single_work = p.work;  // each lane walks its ray alone: the work is the single ray's
    return p;
}

}  // namespace rtsim
