// Reduced-precision box tests (traces/accel/rp_boxes.h) on bvh2 and every wide and compressed BVH,
// plain and compressed leaves: every ray keeps its hit bit for bit and its reference work
// exactly, the plans ask for exactly the work counted (the extra walk's steps included), and the
// extra work never shrinks as the mantissa narrows, ray by ray; the numerical hard cases (rays
// in slab planes, along shared edges, through shared vertices) keep their hits; the other
// structures do not offer it. The AQB8-style quantised box tests of the compressed BVHs
// (StepOptions::quantized_box_tests) drive the same extra walk and keep the same promises.
#include <gtest/gtest.h>

#include "accel_test_util.h"
#include "structure_test_util.h"

namespace rtsim {
namespace {

using test::make_ray;

/// Extra work of `bits` against fp32 on `rays` (both modes); every ray checked. Fills `per_ray`
/// with each ray's rp_steps + rp_tri_tests; when `finer` is given, checks none is below it.
uint64_t check_options(Accel& accel, const StepOptions& reduced, const std::vector<Ray>& rays, const std::string& what,
                       std::vector<uint64_t>* per_ray, const std::vector<uint64_t>* finer) {
    std::unique_ptr<Stepper> fp32 = accel.make_stepper();
    std::unique_ptr<Stepper> narrow = accel.make_stepper(reduced);
    per_ray->clear();
    uint64_t extra = 0;
    int diffs = 0;
    for (const Ray& r : rays)
        for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
            WorkCounts want;
            const Hit hw = trace_with_stepper(*fp32, r, mode, &want);
            const WorkCounts planned = test::tally_plans(*narrow, r, mode);
            const WorkCounts got = narrow->work();
            WorkCounts folded = got;  // the plans show the extra walk as steps and tests
            folded.steps += got.rp_steps;
            folded.box_tests += got.rp_box_tests;
            folded.tri_tests += got.rp_tri_tests;
            // An oriented node's rotations (the walk's and the extra walk's) are the plans' obb operations.
            WorkCounts planned_traced = planned;
            planned_traced.obb_rotations = 0;
            const bool ok = test::same_hit(narrow->hit(), hw, TraversalMode::closest_hit) &&
                            got.traced() == want.traced() && planned_traced == folded.traced() &&
                            planned.obb_rotations == got.obb_rotations && (got.rp_steps == 0 || got.rp_box_hits > 0);
            if (!ok && ++diffs <= 3)
                ADD_FAILURE() << what << ": mode " << int(mode) << " hit " << narrow->hit().prim << "/" << hw.prim
                              << " steps " << got.steps << "/" << want.steps << " planned " << planned.steps;
            const uint64_t x = got.rp_steps + got.rp_tri_tests;
            if (finer && x < (*finer)[per_ray->size()] && ++diffs <= 3)
                ADD_FAILURE() << what << ": ray " << per_ray->size() << " has less extra work than at more bits";
            per_ray->push_back(x);
            extra += x;
        }
    EXPECT_EQ(diffs, 0) << what;
    return extra;
}

uint64_t check_bits(Accel& accel, uint32_t bits, const std::vector<Ray>& rays, const std::string& what,
                    std::vector<uint64_t>* per_ray, const std::vector<uint64_t>* finer) {
    StepOptions reduced;
    reduced.box_precision_bits = bits;
    return check_options(accel, reduced, rays, what, per_ray, finer);
}

StepOptions quantized() {
    StepOptions q;
    q.quantized_box_tests = true;
    return q;
}

TEST(ReducedPrecisionBoxes, ChangeNoHitNorReferenceWorkAndGrowAsBitsShrink) {
    const Scene soup = test::random_soup(5, 3000);
    std::vector<std::string> kinds = {"bvh2", "obvh2"};
    for (const std::string& k : test::wide_kinds()) kinds.push_back(k);
    for (const char* scene_name : {"soup", "cornell", "hairball", "teapot_stadium"}) {
        const Scene& scene = std::string(scene_name) == "soup" ? soup : test::procedural(scene_name);
        const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), 9, 300);
        for (const std::string& kind : test::with_compressed_leaves(kinds)) {
            const auto accel = test::build_kind(scene, kind);
            ASSERT_TRUE(accel->capabilities().reduced_precision_boxes) << kind;
            const std::string what = std::string(scene_name) + " " + kind;
            std::vector<uint64_t> a, b;
            uint64_t previous = 0;
            const std::vector<uint64_t>* finer = nullptr;
            for (uint32_t bits : {22u, 12u, 8u, 4u}) {
                std::vector<uint64_t>& now = finer == &a ? b : a;
                const uint64_t extra = check_bits(*accel, bits, rays, what + " " + std::to_string(bits) + " bits",
                                                  &now, finer);
                EXPECT_GE(extra, previous) << what << " " << bits << " bits";
                previous = extra;
                finer = &now;
            }
            EXPECT_GT(previous, 0u) << what << ": 4 bits should enter some box fp32 does not";
        }
    }
}

/// The hard cases of the wide hard-case tests (test_wide_hard_cases.cpp) through the extra walk.
TEST(ReducedPrecisionBoxes, HardCasesKeepTheirHits) {
    const Scene cube = test::make_scene(test::tessellated_cube(6));
    const Scene sphere = test::make_scene(test::icosphere(3));
    std::vector<Ray> rays;
    Rng rng(31);
    for (int axis = 0; axis < 3; ++axis)  // axis rays with signed zeros along shared edges
        for (float s : {1.0f, -1.0f})
            for (float z : {0.0f, -0.0f})
                for (int i = 1; i < 8; ++i)
                    for (int j = 1; j < 8; ++j) {
                        Vec3 d(z), o(0.0f);
                        d[axis] = s;
                        o[(axis + 1) % 3] = -1.0f + 0.25f * float(i);
                        o[(axis + 2) % 3] = -1.0f + 0.25f * float(j);
                        rays.push_back(make_ray(o, d));
                    }
    for (const Vec3& v : test::tessellated_cube(6))  // through shared vertices, from inside and out
        for (int j = 0; j < 2; ++j) {
            const Vec3 o = j == 0 ? Vec3(0.0f) : test::random_point(rng, Vec3(-3), Vec3(3));
            rays.push_back(make_ray(o, v - o));
        }
    for (int i = 0; i < 500; ++i)  // from inside the closed meshes
        rays.push_back(make_ray(test::random_direction(rng) * 0.9f * std::cbrt(rng.next()), test::random_direction(rng)));
    std::vector<std::string> kinds = {"bvh2"};
    for (const std::string& k : test::wide_kinds()) kinds.push_back(k);
    for (const Scene* scene : {&cube, &sphere})
        for (const std::string& kind : test::with_compressed_leaves(kinds)) {
            const auto accel = test::build_kind(*scene, kind, 2);
            std::vector<uint64_t> per_ray;
            for (uint32_t bits : {8u, 3u}) check_bits(*accel, bits, rays, kind + " hard cases", &per_ray, nullptr);
        }
}

TEST(QuantizedBoxTests, ChangeNoHitNorReferenceWorkAndWalkMore) {
    for (const char* scene_name : {"cornell", "hairball", "teapot_stadium"}) {
        const Scene& scene = test::procedural(scene_name);
        const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), 13, 300);
        for (const std::string& kind : test::with_compressed_leaves({"cwbvh6", "cwbvh8", "cwbvh8_octant"})) {
            const auto accel = test::build_kind(scene, kind);
            ASSERT_TRUE(accel->capabilities().quantized_boxes) << kind;
            std::vector<uint64_t> per_ray;
            const uint64_t extra = check_options(*accel, quantized(), rays, std::string(scene_name) + " " + kind,
                                                 &per_ray, nullptr);
            // One grid cell of slack enters boxes the fp32 test rejects, but not many.
            EXPECT_GT(extra, 0u) << scene_name << " " << kind;
        }
    }
}

TEST(QuantizedBoxTests, HardCasesKeepTheirHits) {
    const Scene cube = test::make_scene(test::tessellated_cube(6));
    std::vector<Ray> rays;
    for (int axis = 0; axis < 3; ++axis)  // rays in the cube's face planes and along its edges
        for (int i = 0; i <= 8; ++i) {
            Vec3 o(0.0f), d(0.0f);
            o[axis] = -3.0f;
            o[(axis + 1) % 3] = -1.0f + 0.25f * float(i);
            o[(axis + 2) % 3] = 1.0f;
            d[axis] = 1.0f;
            rays.push_back(make_ray(o, d));
        }
    for (const Vec3& v : test::tessellated_cube(6)) rays.push_back(make_ray(Vec3(0.0f), v));  // through vertices
    for (const std::string& kind : {"cwbvh6", "cwbvh8"}) {
        const auto accel = test::build_kind(cube, kind, 2);
        std::vector<uint64_t> per_ray;
        check_options(*accel, quantized(), rays, kind + " hard cases", &per_ray, nullptr);
    }
}

TEST(QuantizedBoxTests, Fp32NodesDoNotOfferThem) {
    const Scene scene = test::random_soup(3, 500);
    for (const std::string kind : {"bvh2", "bvh4", "bvh8", "kdtree", "grid"})
        EXPECT_FALSE(test::build_kind(scene, kind)->capabilities().quantized_boxes) << kind;
}

TEST(ReducedPrecisionBoxes, OtherStructuresDoNotOfferIt) {
    const Scene scene = test::random_soup(3, 500);
    for (const std::string kind : {"grid", "kdtree", "octree", "bih"})
        EXPECT_FALSE(test::build_kind(scene, kind)->capabilities().reduced_precision_boxes) << kind;
}

}  // namespace
}  // namespace rtsim
