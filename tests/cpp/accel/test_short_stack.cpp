// Short stacks with a restart trail (traces/accel/short_stack.h): on every BVH kind, the kd-tree
// (kd-restart with push-down) and the BIH, and any stack size, every ray keeps its hit bit for bit and its reference work exactly (the restarts' work is
// counted only in the model's own fields), the plans ask for exactly the work counted (revisits
// included), a stack as deep as the structure can need never restarts, and a short stack on a
// deep scene does restart.
#include <gtest/gtest.h>

#include "accel_test_util.h"
#include "structure_test_util.h"

namespace rtsim {
namespace {

std::string work_text(const WorkCounts& w) {
    std::string s;
    for (const WorkFieldInfo& f : kWorkFields)
        if (w.*f.member) s += std::string(f.name) + "=" + std::to_string(w.*f.member) + " ";
    return s;
}

struct Totals {
    uint64_t drops = 0, restarts = 0, restart_steps = 0, steps = 0;
};

/// Checks every ray of `rays` (both modes) against the full stack; returns the restarts' totals.
Totals check_short_stack(Accel& accel, uint32_t entries, const std::vector<Ray>& rays, const std::string& what) {
    const bool planes = accel.kind() == "kdtree" || accel.kind() == "bih";
    StepOptions shorter;
    shorter.short_stack_entries = entries;
    std::unique_ptr<Stepper> full = accel.make_stepper();
    std::unique_ptr<Stepper> shortened = accel.make_stepper(shorter);
    Totals t;
    int diffs = 0;
    for (const Ray& r : rays)
        for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
            WorkCounts want, got;
            const Hit hw = trace_with_stepper(*full, r, mode, &want);
            const WorkCounts planned = test::tally_plans(*shortened, r, mode);
            got = shortened->work();
            const Hit hg = shortened->hit();
            // The plans show revisits as node steps with box tests (a space partition's: plane tests).
            WorkCounts folded = got;
            folded.steps += got.restart_steps;
            (planes ? folded.plane_tests : folded.box_tests) += got.restart_box_tests;
            // An oriented node's rotations (its steps' and its revisits') are the plans' obb operations.
            WorkCounts planned_traced = planned;
            planned_traced.obb_rotations = 0;
            const bool ok = test::same_hit(hg, hw, TraversalMode::closest_hit) && got.traced() == want.traced() &&
                            planned_traced == folded.traced() && planned.obb_rotations == got.obb_rotations &&
                            got.restart_steps >= got.restarts;
            if (!ok && ++diffs <= 3)
                ADD_FAILURE() << what << ": mode " << int(mode) << " hit " << hg.prim << "/" << hw.prim << " steps "
                              << got.steps << "/" << want.steps << " restarts " << got.restarts << " planned "
                              << work_text(planned_traced) << " folded " << work_text(folded.traced()) << " obb "
                              << planned.obb_rotations << "/" << got.obb_rotations;
            t.drops += got.stack_drops;
            t.restarts += got.restarts;
            t.restart_steps += got.restart_steps;
            t.steps += got.steps;
        }
    EXPECT_EQ(diffs, 0) << what;
    return t;
}

TEST(ShortStack, ChangesNoHitNorReferenceWorkAndRestartsOnlyWhenShort) {
    const Scene soup = test::random_soup(5, 3000);
    for (const char* scene_name : {"soup", "hairball"}) {
        const Scene& scene = std::string(scene_name) == "soup" ? soup : test::procedural(scene_name);
        const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), 7, 1500);
        for (const std::string kind : {"bvh2", "obvh2", "bvh4", "bvh8", "cwbvh8", "kdtree", "bih"}) {
            const auto accel = test::build_kind(scene, kind);
            ASSERT_TRUE(accel->capabilities().restart_trail) << kind;
            const std::string what = std::string(scene_name) + " " + kind;
            const Totals one = check_short_stack(*accel, 1, rays, what + " 1 entry");
            const Totals four = check_short_stack(*accel, 4, rays, what + " 4 entries");
            const Totals deep = check_short_stack(*accel, accel->max_stack_entries(), rays, what + " deepest");
            EXPECT_GT(one.restarts, 0u) << what;
            EXPECT_GT(one.drops, 0u) << what;
            EXPECT_GE(one.restart_steps, four.restart_steps) << what;
            EXPECT_EQ(deep.restarts, 0u) << what;
            EXPECT_EQ(deep.drops, 0u) << what;
            EXPECT_EQ(deep.restart_steps, 0u) << what;
        }
    }
}

TEST(ShortStack, KdRestartPushesDownBelowTheRoot) {
    // kd-restart with push-down (Foley & Sugerman 2005) re-descends from the deepest node that
    // holds what is left, the BIH's trail from the root: the kd-tree revisits fewer nodes per
    // restart than a walk from the root would (the path to the resumed entry).
    const Scene& scene = test::procedural("hairball");
    const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), 17, 800);
    const auto kd = test::build_kind(scene, "kdtree");
    StepOptions o;
    o.short_stack_entries = 1;
    std::unique_ptr<Stepper> s = kd->make_stepper(o);
    uint64_t restarts = 0, revisits = 0, root_revisits = 0;
    for (const Ray& r : rays) {
        s->begin(r, TraversalMode::closest_hit);
        while (!s->done()) {
            if (s->plan().locality == 0 && s->work().restarts > 0) ++root_revisits;
            s->execute();
        }
        restarts += s->work().restarts;
        revisits += s->work().restart_steps;
    }
    EXPECT_GT(restarts, 0u);
    EXPECT_GE(revisits, restarts);
    EXPECT_LT(root_revisits, restarts);  // many restarts start below the root
}

TEST(ShortStack, OtherStructuresDoNotOfferIt) {
    const Scene scene = test::random_soup(3, 500);
    for (const std::string kind : {"grid", "octree"})
        EXPECT_FALSE(test::build_kind(scene, kind)->capabilities().restart_trail) << kind;
}

}  // namespace
}  // namespace rtsim
