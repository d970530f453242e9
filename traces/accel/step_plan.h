#pragma once
// The seam between an acceleration structure and whatever times it (docs/architecture.md, "The
// acceleration-structure seam"): a StepPlan is plain data saying what a ray's next traversal step
// fetches (addresses in the one memory image, bytes, data kind) and which operations it runs on
// the fetched data (box tests, triangle tests, ...). The model's traversal units and the analytic
// level consume plans only; neither knows which structure produced them.
#include <cstdint>

#include "traces/common/data_kind.h"
#include "traces/common/op_kind.h"
#include "traces/common/prefetch.h"

namespace rtsim {

/// One read the step needs before its operations can run.
struct Fetch {
    uint64_t addr = 0;
    uint32_t bytes = 0;
    DataKind kind = DataKind::node;
};

/// `count` operations of one kind (a pipeline of width w takes ceil(count / w) issues).
struct Op {
    OpKind kind = OpKind::box;
    uint32_t count = 0;
};

/// Locality key of a step that stays where the ray is (e.g. a BVH leaf: its triangles belong to
/// the treelet of the node that references them).
constexpr uint32_t kNoLocality = 0xFFFFFFFFu;

/// What one ray's next step fetches and runs. The fetches are independent (issued together);
/// the operations run in order once all fetched data has arrived.
struct StepPlan {
    static constexpr int kMaxFetches = 8;
    static constexpr int kMaxOps = 4;

    bool done = true;                 ///< the ray has finished: hit() and work() are final
    uint32_t locality = kNoLocality;  ///< the step's node or cell, for treelet partitions
    uint8_t fetch_count = 0;
    uint8_t op_count = 0;
    Fetch fetch[kMaxFetches];
    Op op[kMaxOps];
    /// The host's copy of the data execute() reads first (null: not given). Simulation speed
    /// only: a driver interleaving other rays prefetches it again just before the step runs.
    const void* host = nullptr;
    uint32_t host_bytes = 0;

    void reset(uint32_t locality_key) {
        done = false;
        locality = locality_key;
        fetch_count = op_count = 0;
        host = nullptr;
    }
    void finish() {
        done = true;
        locality = kNoLocality;
        fetch_count = op_count = 0;
        host = nullptr;
    }
    /// Records the host data the step reads and prefetches it into the host's cache now.
    void set_host(const void* data, uint32_t bytes) {
        host = data;
        host_bytes = bytes;
        prefetch_range(data, bytes);
    }
    void add_fetch(uint64_t addr, uint32_t bytes, DataKind kind) { fetch[fetch_count++] = Fetch{addr, bytes, kind}; }
    void add_op(OpKind kind, uint32_t count) { op[op_count++] = Op{kind, count}; }
    /// A leaf's tests: triangles, spheres and capsules each to their pipeline (a kind with no
    /// test adds no operation, but a leaf always issues one). `times`: rays testing each (a
    /// packet's).
    template <class Tests>
    void add_leaf_ops(const Tests& t, uint32_t times = 1) {
        if (t.triangles || (!t.spheres && !t.capsules)) add_op(OpKind::triangle, t.triangles * times);
        if (t.spheres) add_op(OpKind::sphere, t.spheres * times);
        if (t.capsules) add_op(OpKind::capsule, t.capsules * times);
    }
};

/// Operations a step's results called for beyond its plan (alpha tests of the triangles hit).
struct StepOutcome {
    static constexpr int kMaxOps = 2;
    uint8_t op_count = 0;
    Op op[kMaxOps];
    void add_op(OpKind kind, uint32_t count) {
        if (count) op[op_count++] = Op{kind, count};
    }
};

}  // namespace rtsim
