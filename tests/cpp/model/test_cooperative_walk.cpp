// Cooperative lanes' recorded walks (rtl_model/traversal/simt/cooperation.h): a ray's walk stepped
// ahead has the sequential walk's hit, work and steps; its steps form a tree whose every step
// depends on an earlier one; taking every ready step round by round runs each step once, and
// the reads are the sequential walk's; taken one at a time, earliest first, they come in the
// sequential order; and the tree is wider than a chain (rays have independent subtrees).
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "rtl_model/traversal/simt/cooperation.h"
#include "tests/cpp/accel/accel_test_util.h"
#include "tests/cpp/accel/structure_test_util.h"

namespace rtsim {
namespace {

StepCosts costs() {
    StepCosts c;
    c.stack_entries = 8;
    c.stack_entry_bytes = 8;
    for (uint32_t& w : c.width) w = 1;
    return c;
}

std::vector<uint64_t> sequential_reads(Stepper& s, const Ray& r, TraversalMode mode, WorkCounts* work, Hit* hit) {
    std::vector<uint64_t> out;
    s.begin(r, mode);
    while (!s.plan().done) {
        for (int i = 0; i < s.plan().fetch_count; ++i) out.push_back(s.plan().fetch[i].addr);
        s.execute();
    }
    *work = s.work();
    *hit = s.hit();
    return out;
}

/// Takes steps until the walk is done: every ready step each round (`all`), or the earliest
/// ready one; returns the reads in the order taken and counts the rounds.
std::vector<uint64_t> run_walk(CooperativeWalk& walk, bool all, size_t* rounds) {
    std::vector<uint64_t> out;
    StepDemand d;
    *rounds = 0;
    while (!walk.done()) {
        walk.release();
        ++*rounds;
        bool took = false;
        for (uint32_t cls = 0; cls <= kOpKindCount; ++cls)
            while (walk.ready(cls) > 0 && (all || !took)) {
                if (!all && walk.next_class(kOpKindCount) != cls) break;
                walk.take(cls, d, [&](const Fetch& f) { out.push_back(f.addr); }, [](const Fetch&) {});
                took = true;
            }
        EXPECT_TRUE(took) << "a walk that is not done has a ready step";
        if (!took) break;
    }
    return out;
}

TEST(CooperativeWalk, KeepsTheSequentialWalkAndExposesItsSubtrees) {
    const Scene& scene = test::procedural("hairball");
    const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), 17, 200);
    const StepCosts c = costs();
    for (const char* kind : {"bvh2", "bvh8", "cwbvh6"}) {
        const auto accel = test::build_kind(scene, kind);
        std::unique_ptr<Stepper> seq = accel->make_stepper();
        std::unique_ptr<Stepper> rec = accel->make_stepper();
        size_t steps = 0, parallel_rounds = 0;
        for (const Ray& r : rays)
            for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
                WorkCounts want;
                Hit want_hit;
                const std::vector<uint64_t> order = sequential_reads(*seq, r, mode, &want, &want_hit);
                rec->begin(r, mode);
                StackSplit stack;
                CooperativeWalk walk;
                walk.record(*rec, stack, &c);
                ASSERT_TRUE(rec->done());
                EXPECT_TRUE(test::same_hit(rec->hit(), want_hit)) << kind;
                EXPECT_EQ(rec->work(), want) << kind;
                // One at a time, earliest first: the sequential order.
                size_t rounds = 0;
                EXPECT_EQ(run_walk(walk, false, &rounds), order) << kind;
                // Every ready step each round: each step once, the same reads, fewer rounds.
                rec->begin(r, mode);
                stack = StackSplit{};
                walk.record(*rec, stack, &c);
                std::vector<uint64_t> all = run_walk(walk, true, &rounds), sorted = order;
                std::sort(all.begin(), all.end());
                std::sort(sorted.begin(), sorted.end());
                EXPECT_EQ(all, sorted) << kind;
                EXPECT_LE(rounds, walk.steps()) << kind;
                steps += walk.steps();
                parallel_rounds += rounds;
            }
        // The critical path is shorter than the walk: subtrees a helper can take exist.
        EXPECT_LT(parallel_rounds * 10, steps * 9) << kind << ": " << parallel_rounds << " rounds, " << steps << " steps";
    }
}

}  // namespace
}  // namespace rtsim
