// Stepper::stack_reads, which stack-driven prefetching (traversal.stack_prefetch, TTP) requests:
// on every structure that declares stack_addresses, the read it gives for the stack's top entry
// is exactly the fetch of the step that entry becomes when it is popped (and not skipped), for
// closest-hit and any-hit rays; structures that do not declare it give none.
#include <gtest/gtest.h>

#include "accel_test_util.h"
#include "structure_test_util.h"

namespace rtsim {
namespace {

struct Recorded {
    int size = 0;  ///< stack entries when recorded; the top was entry size - 1
    Fetch top;
};

/// Walks every ray, recording the top entry's read at each step, and checks it against the plan
/// of the step where that entry is popped and taken (the stack then holds size - 1 entries).
int check_top_reads(Accel& accel, const std::vector<Ray>& rays, const std::string& what) {
    std::unique_ptr<Stepper> s = accel.make_stepper();
    int checked = 0, diffs = 0;
    for (const Ray& r : rays)
        for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
            s->begin(r, mode);
            std::vector<Recorded> open;  // entries on the stack, oldest first
            while (!s->plan().done) {
                s->execute();
                const int n = s->stack_size();
                // Entries at or above the new size were popped by this step.
                bool taken = false;
                Recorded popped;
                while (!open.empty() && open.back().size > n) {
                    popped = open.back();
                    taken = popped.size == n + 1;
                    open.pop_back();
                }
                if (taken && !s->plan().done) {
                    // The entry at index n was popped: it is this plan unless the pop skipped
                    // it and took a deeper one (then the stack would be shorter still).
                    const Fetch& f = s->plan().fetch[0];
                    ++checked;
                    if ((f.addr != popped.top.addr || f.bytes != popped.top.bytes || f.kind != popped.top.kind) &&
                        ++diffs <= 3)
                        ADD_FAILURE() << what << ": popped entry read " << popped.top.addr << "+" << popped.top.bytes
                                      << ", the step fetches " << f.addr << "+" << f.bytes;
                }
                Fetch top[2];
                const uint32_t got = s->stack_reads(top, 2);
                EXPECT_EQ(got, uint32_t(std::min(n, 2))) << what;
                if (n > 0 && (open.empty() || open.back().size < n)) open.push_back({n, top[0]});
            }
        }
    EXPECT_EQ(diffs, 0) << what;
    return checked;
}

TEST(StackReads, TopEntryIsTheStepItsPopTakes) {
    const Scene& scene = test::procedural("hairball");
    const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), 7, 400);
    for (const char* kind : {"bvh2", "bvh4", "bvh8", "cwbvh6", "cwbvh8", "gkbvh"}) {
        const auto accel = test::build_kind(scene, kind);
        ASSERT_TRUE(accel->capabilities().stack_addresses) << kind;
        EXPECT_GT(check_top_reads(*accel, rays, kind), 1000) << kind;
    }
}

TEST(StackReads, StructuresWithoutStackAddressesGiveNone) {
    const Scene& scene = test::procedural("hairball");
    const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), 7, 50);
    for (const char* kind : {"kdtree", "bih", "grid", "octree"}) {
        const auto accel = test::build_kind(scene, kind);
        EXPECT_FALSE(accel->capabilities().stack_addresses) << kind;
        std::unique_ptr<Stepper> s = accel->make_stepper();
        Fetch out[2];
        for (const Ray& r : rays) {
            s->begin(r, TraversalMode::closest_hit);
            while (!s->plan().done) {
                s->execute();
                EXPECT_EQ(s->stack_reads(out, 2), 0u) << kind;
            }
        }
    }
}

}  // namespace
}  // namespace rtsim
