#pragma once
// Everything a ray in flight carries between a traversal unit and the ray buffer: its stepper
// (ray, hit so far, traversal stack, work counts; any structure behind the seam) and the model's
// bookkeeping of its stack. Moving a ray moves a pointer, not its state.
#include <cstdint>
#include <memory>
#include <vector>

#include "rtl_model/common/interfaces.h"
#include "rtl_model/common/stack_split.h"
#include "traces/accel/accel.h"

namespace rtsim {

struct RayState {
    std::unique_ptr<Stepper> stepper;
    uint64_t ray_id = 0;
    RayKind kind = RayKind::primary;  ///< what the ray is (per-kind figures: SIMD efficiency by kind)
    Cycle start = 0;           ///< cycle the ray entered the machine (latency is measured from it)
    StackSplit stack;          ///< its stack entries on chip and spilled to memory
};

/// Steppers for rays in flight, reused: a free list over the structure's make_stepper(options).
class StepperPool {
public:
    StepperPool(const Accel& accel, const StepOptions& options) : m_accel(accel), m_options(options) {}
    std::unique_ptr<Stepper> acquire() {
        if (m_free.empty()) return m_accel.make_stepper(m_options);
        std::unique_ptr<Stepper> s = std::move(m_free.back());
        m_free.pop_back();
        return s;
    }
    void release(std::unique_ptr<Stepper> s) {
        if (s) m_free.push_back(std::move(s));
    }
    /// The structure the steppers walk (a packet unit makes packet steppers from it).
    const Accel& accel() const { return m_accel; }
    /// What the steppers walk with (a packet unit's packet steppers too).
    const StepOptions& options() const { return m_options; }

private:
    const Accel& m_accel;
    const StepOptions m_options;
    std::vector<std::unique_ptr<Stepper>> m_free;
};

/// Bytes of ray-buffer SRAM one waiting ray occupies: origin, direction, tmin, tmax (32), hit so
/// far (prim, t, u, v: 16), ray id and flags (8), its on-chip stack entries and its mailbox.
inline uint32_t ray_state_bytes(uint32_t stack_entries, uint32_t stack_entry_bytes, uint32_t mailbox_bytes = 0) {
    return 32 + 16 + 8 + stack_entries * stack_entry_bytes + mailbox_bytes;
}

/// The ray buffer as the traversal units see it (treelet scheduling).
/// Contract: take() hands each waiting ray to exactly one consumer; park() accepts every ray (it
/// overflows to memory when the SRAM is full), so units never block on it.
class RayBufferIf : public virtual sc_core::sc_interface {
public:
    /// Next ray of `consumer`'s current treelet, choosing a new treelet for it when that queue is
    /// empty and `may_switch` (else false). A consumer is what runs one treelet at a time: a MIMD
    /// unit, or one warp of a SIMT unit (UnitKind::treelet_consumers). False when no ray can be
    /// run now. *ready: cycle the ray's state is in the unit.
    virtual bool take(uint32_t consumer, Cycle time, RayState* ray, uint32_t* treelet, Cycle* ready,
                      bool may_switch = true) = 0;
    /// A ray leaves its treelet for `treelet`; returns the cycle its state is written.
    virtual Cycle park(uint32_t treelet, RayState&& ray, Cycle time) = 0;
    /// A ray finished (its hit was written).
    virtual void finished(Cycle time) = 0;
    /// No ray is left anywhere: not in dispatch, not in queues, not in flight.
    virtual bool done() const = 0;
};

}  // namespace rtsim
