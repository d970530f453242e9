#pragma once
// Work one ray caused in the reference traversal; the model must count the same (docs/accel.md).
// Names are neutral so every acceleration structure reports in them.
//
// Every counter is declared once, in RTSIM_WORK_FIELDS: WorkCounts' members, the trace's WORK
// record, the hit checker's totals and messages, the analytic level's sums, the energy model's
// prices, the Python bindings and the trace dtypes all iterate it, so adding a counter is one
// line here plus the code that counts it (and a trace-format version bump: WORK records grow; the
// reader widens older versions' records, trace_reader.cpp).
// Counters of the model alone (never in a trace) are declared in RTSIM_MODEL_WORK_FIELDS.
#include <array>
#include <cstddef>
#include <cstdint>

#include "traces/common/op_kind.h"

// X(name, tests_of, plan_step, doc)
//   tests_of:  the operation kind whose tests the field counts (what a pipeline of that kind
//              does for the ray), or kNoOpKind
//   plan_step: the field counts steps a traversal unit plans (each a fetch, then operations)
#define RTSIM_WORK_FIELDS(X)                                                                        \
    X(steps, kNoOpKind, true, "traversal steps that fetched a node or a cell")                     \
    X(box_tests, OpKind::box, false, "ray/box tests (a node's child boxes, a grid's bounds)")      \
    X(tri_tests, OpKind::triangle, false, "ray/triangle tests")                                    \
    X(anyhit_calls, OpKind::anyhit, false, "alpha-mask (any-hit) evaluations on MASK triangles")   \
    X(transforms, OpKind::transform, false, "instance transforms (two-level structures)")         \
    X(cell_steps, OpKind::cell, true, "3D-DDA steps from cell to cell (grids)")                    \
    X(plane_tests, OpKind::plane, false, "ray/split-plane tests (kd-trees, BIH)")                  \
    X(refs, kNoOpKind, false, "primitive references fetched (structures with index lists)")       \
    X(sphere_tests, OpKind::sphere, false, "ray/sphere tests (curved primitives)")              \
    X(capsule_tests, OpKind::capsule, false, "ray/capsule tests (curved primitives)")

// The mailbox's counts (docs/accel.md, "Mailboxes"): never in a trace (a trace's work is the
// structure's without one). With a mailbox tri_tests counts the tests run, and
// tri_tests + mailbox_hits equals the triangle tests without one.
// A short stack's counts (docs/accel.md, "Short stacks"): the work its restarts add on top of
// the full stack's, which the reference fields keep counting unchanged. The TLAS's share of a
// two-level walk's steps and box tests (docs/accel.md, "Two-level structures"). The extra work of
// a reduced-precision box pipeline: the subtrees its looser test enters that the fp32 test does
// not (docs/accel.md, "Reduced-precision box tests"), on top of the reference work. The rotations
// of an oriented BVH (docs/accel.md, "Oriented boxes"): one per step at an oriented node, so the
// steps and the image determine them and the trace need not carry them.
#define RTSIM_MODEL_WORK_FIELDS(X)                                                                  \
    X(mailbox_lookups, kNoOpKind, false, "primitive references looked up in the ray's mailbox")    \
    X(mailbox_hits, kNoOpKind, false, "references found there: triangle neither fetched nor tested") \
    X(stack_drops, kNoOpKind, false, "short stack: oldest entries dropped by a push onto a full one") \
    X(restarts, kNoOpKind, false, "short stack: restarts from the root (empty, entries dropped)")  \
    X(restart_steps, kNoOpKind, true, "short stack: node steps a restart's re-descent revisited")  \
    X(restart_box_tests, kNoOpKind, false, "short stack: box tests of those revisits")           \
    X(tlas_steps, kNoOpKind, false, "two-level: the steps that walked the TLAS (also in steps)")    \
    X(tlas_box_tests, kNoOpKind, false, "two-level: their box tests (also in box_tests)")         \
    X(rp_box_hits, kNoOpKind, false, "reduced-precision boxes: entered, though fp32 rejects or culls them") \
    X(rp_steps, kNoOpKind, true, "reduced-precision boxes: node steps inside those boxes")           \
    X(rp_box_tests, kNoOpKind, false, "reduced-precision boxes: box tests of those steps")          \
    X(rp_tri_tests, kNoOpKind, false, "reduced-precision boxes: primitive tests in their leaves (no hit; curved ones priced as triangles)") \
    X(obb_rotations, OpKind::obb, false, "oriented boxes: ray rotations into oriented nodes' frames (obvh2)")

#define RTSIM_ALL_WORK_FIELDS(X) RTSIM_WORK_FIELDS(X) RTSIM_MODEL_WORK_FIELDS(X)

namespace rtsim {

/// The work fields by position (WORK record order, then the model's own).
enum class WorkField : uint8_t {
#define RTSIM_WORK_ENUM(name, tests_of, plan_step, doc) name,
    RTSIM_ALL_WORK_FIELDS(RTSIM_WORK_ENUM)
#undef RTSIM_WORK_ENUM
};
#define RTSIM_WORK_ONE(name, tests_of, plan_step, doc) +1
constexpr int kWorkFieldCount = 0 RTSIM_ALL_WORK_FIELDS(RTSIM_WORK_ONE);
/// The fields a trace records (the first ones).
constexpr int kTracedWorkFieldCount = 0 RTSIM_WORK_FIELDS(RTSIM_WORK_ONE);
#undef RTSIM_WORK_ONE

struct WorkCounts {
#define RTSIM_WORK_MEMBER(name, tests_of, plan_step, doc) uint32_t name = 0;
    RTSIM_ALL_WORK_FIELDS(RTSIM_WORK_MEMBER)
#undef RTSIM_WORK_MEMBER

    uint32_t& operator[](WorkField f);
    uint32_t operator[](WorkField f) const;
    WorkCounts& operator+=(const WorkCounts& o);
    bool operator==(const WorkCounts& o) const;
    bool operator!=(const WorkCounts& o) const { return !(*this == o); }
    /// The counts the same traversal has without a mailbox (what a trace records): the skipped
    /// tests counted back, the mailbox's own counts dropped.
    WorkCounts without_mailbox() const {
        WorkCounts w = *this;
        w.tri_tests += mailbox_hits;
        w.mailbox_lookups = w.mailbox_hits = 0;
        return w;
    }
    /// What a trace records for the same traversal: without the mailbox, without a short
    /// stack's restarts and reduced-precision boxes' extra work (both on top of the reference
    /// walk's), the TLAS's share and an oriented BVH's rotations.
    WorkCounts traced() const {
        WorkCounts w = without_mailbox();
        w.stack_drops = w.restarts = w.restart_steps = w.restart_box_tests = 0;
        w.tlas_steps = w.tlas_box_tests = 0;
        w.rp_box_hits = w.rp_steps = w.rp_box_tests = w.rp_tri_tests = 0;
        w.obb_rotations = 0;
        return w;
    }
};

/// One field's declaration.
struct WorkFieldInfo {
    const char* name;
    uint32_t WorkCounts::*member;
    OpKind tests_of;  ///< kNoOpKind: the field counts no pipeline's tests
    bool plan_step;
    const char* doc;
    bool traced;  ///< in a trace's WORK record (false: the model's own count)
};
inline constexpr std::array<WorkFieldInfo, kWorkFieldCount> kWorkFields{{
#define RTSIM_WORK_INFO(name, tests_of, plan_step, doc) {#name, &WorkCounts::name, tests_of, plan_step, doc, true},
    RTSIM_WORK_FIELDS(RTSIM_WORK_INFO)
#undef RTSIM_WORK_INFO
#define RTSIM_WORK_INFO(name, tests_of, plan_step, doc) {#name, &WorkCounts::name, tests_of, plan_step, doc, false},
    RTSIM_MODEL_WORK_FIELDS(RTSIM_WORK_INFO)
#undef RTSIM_WORK_INFO
}};

inline uint32_t& WorkCounts::operator[](WorkField f) { return this->*kWorkFields[size_t(f)].member; }
inline uint32_t WorkCounts::operator[](WorkField f) const { return this->*kWorkFields[size_t(f)].member; }
inline WorkCounts& WorkCounts::operator+=(const WorkCounts& o) {
    for (const WorkFieldInfo& f : kWorkFields) this->*f.member += o.*f.member;
    return *this;
}
inline bool WorkCounts::operator==(const WorkCounts& o) const {
    for (const WorkFieldInfo& f : kWorkFields)
        if (this->*f.member != o.*f.member) return false;
    return true;
}

/// The field counting the tests of `kind`; throws rtsim::Error naming the kind when none does.
WorkField work_field_of(OpKind kind);
/// Sum of the fields that count plan steps (what a unit's scheduler sees per ray, less the ray's own slot).
double plan_step_work(const WorkCounts& w);

/// Work summed over many rays (64-bit: a frame's box tests overflow 32 bits).
struct WorkTotals {
    std::array<uint64_t, kWorkFieldCount> field{};
    uint64_t operator[](WorkField f) const { return field[size_t(f)]; }
    uint64_t& operator[](WorkField f) { return field[size_t(f)]; }
    void add(const WorkCounts& w) {
        for (size_t i = 0; i < field.size(); ++i) field[i] += w.*kWorkFields[i].member;
    }
};

}  // namespace rtsim
