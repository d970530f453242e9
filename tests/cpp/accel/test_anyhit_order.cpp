// Any-hit child orders (StepOptions::anyhit_order) on every BVH that offers them (binary, oriented,
// wide, compressed and octant-ordered): every order gives the same
// occlusion answer as nearest-first, closest-hit rays keep their hit and work bit for bit, the
// plans ask for exactly the work counted, trace() with the options walks as the stepper does,
// and the orders really differ (some any-hit ray takes a different number of steps).
#include <gtest/gtest.h>

#include "accel_test_util.h"
#include "structure_test_util.h"

namespace rtsim {
namespace {

struct OrderTotals {
    uint64_t steps = 0;
    int rays_walked_otherwise = 0;
};

OrderTotals check_order(Accel& accel, AnyHitOrder order, const std::vector<Ray>& rays, const std::string& what) {
    StepOptions options;
    options.anyhit_order = order;
    std::unique_ptr<Stepper> nearest = accel.make_stepper();
    std::unique_ptr<Stepper> ordered = accel.make_stepper(options);
    OrderTotals t;
    int diffs = 0;
    for (const Ray& r : rays)
        for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
            WorkCounts want, got, traced;
            const Hit hw = trace_with_stepper(*nearest, r, mode, &want);
            const WorkCounts planned = test::tally_plans(*ordered, r, mode);
            got = ordered->work();
            const Hit hg = ordered->hit();
            const Hit ht = accel.trace(r, mode, &traced, options);
            bool ok = test::same_hit(hg, hw, mode) && planned == got && traced == got &&
                      test::same_hit(ht, hg, TraversalMode::closest_hit);
            if (mode == TraversalMode::closest_hit) ok = ok && test::same_hit(hg, hw, mode) && got == want;
            else t.steps += got.steps, t.rays_walked_otherwise += got.steps != want.steps;
            if (!ok && ++diffs <= 3)
                ADD_FAILURE() << what << ": mode " << int(mode) << " hit " << hg.prim << "/" << hw.prim << " steps "
                              << got.steps << "/" << want.steps;
        }
    EXPECT_EQ(diffs, 0) << what;
    return t;
}

TEST(AnyHitOrder, KeepsOcclusionAndClosestHitsAndChangesTheWalk) {
    const Scene soup = test::random_soup(5, 3000);
    for (const char* scene_name : {"soup", "hairball"}) {
        const Scene& scene = std::string(scene_name) == "soup" ? soup : test::procedural(scene_name);
        const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), 11, 1500);
        for (const char* kind : {"bvh2", "obvh2", "bvh4", "bvh8", "cwbvh8", "bvh8_octant"}) {
            const auto accel = test::build_kind(scene, kind);
            ASSERT_TRUE(accel->capabilities().anyhit_order) << kind;
            for (AnyHitOrder order : {AnyHitOrder::nearest, AnyHitOrder::largest_box, AnyHitOrder::fixed}) {
                const std::string what = std::string(scene_name) + " " + kind + " order " + std::to_string(int(order));
                const OrderTotals t = check_order(*accel, order, rays, what);
                if (order == AnyHitOrder::nearest) EXPECT_EQ(t.rays_walked_otherwise, 0) << what;
                else EXPECT_GT(t.rays_walked_otherwise, 0) << what;
            }
        }
    }
}

}  // namespace
}  // namespace rtsim
