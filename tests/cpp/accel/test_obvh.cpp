// The oriented BVH (obvh2) beyond what the space-partitioning tests sweep (hits against brute
// force and bvh2 on soups and the axis-aligned hard cases: test_space_partition.cpp): its
// rotation table, the fit (every triangle inside every box on its path, in each node's frame;
// rotated geometry gets oriented nodes and a lower SAH cost), hard cases on geometry lying in a
// rotated frame (rays along its faces and edges, through its vertices, at large and small
// scales), the work an oriented step adds, and validation of corrupt images.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "space_partition_util.h"
#include "traces/accel/obvh/obvh.h"
#include "traces/bvh/build_tree.h"
#include "traces/bvh/refit.h"
#include "traces/common/error.h"
#include "traces/common/rng.h"
#include "traces/scene/procedural.h"

namespace rtsim {
namespace {

using test::build_named;
using test::expect_structure_correct;

const ObvhAccel& obvh(const Accel& a) { return static_cast<const ObvhAccel&>(a); }

void expect_orthonormal(const std::vector<Rotation>& table) {
    for (const Rotation& m : table)
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                double dot = 0;
                for (int k = 0; k < 3; ++k) dot += double(m[3 * i + k]) * m[3 * j + k];
                EXPECT_NEAR(dot, i == j ? 1.0 : 0.0, 1e-6);
            }
}

/// A table of tilted frames only (no rotations about one axis).
ObbConfig tilted(uint32_t turns, uint32_t tilts) {
    ObbConfig c;
    c.angle_steps = 1, c.turn_steps = turns, c.tilt_steps = tilts;
    return c;
}

TEST(Obvh, RotationTableIsOrthonormalAndFitsSevenBits) {
    for (uint32_t steps : {2u, 16u, 32u, 43u}) {
        ObbConfig c;
        c.angle_steps = steps;
        const std::vector<Rotation> table = obb_rotation_table(c);
        EXPECT_EQ(table.size(), 3 * (steps - 1));
        EXPECT_LT(table.size(), size_t(kNoRotation));
        expect_orthonormal(table);
    }
    // Tilted frames: every turn with every tilt but none, after the rotations about one axis.
    // An even tilt count skips its quarter tilt, a turn about z again.
    for (auto [turns, tilts] : {std::pair{12u, 11u}, std::pair{1u, 3u}, std::pair{63u, 3u}, std::pair{4u, 4u}}) {
        const std::vector<Rotation> table = obb_rotation_table(tilted(turns, tilts));
        EXPECT_EQ(table.size(), turns * (tilts - 1 - (tilts % 2 == 0)));
        expect_orthonormal(table);
    }
    ObbConfig both = tilted(9, 9);
    both.angle_steps = 16;
    EXPECT_EQ(obb_rotation_table(both).size(), 45u + 72u);
    EXPECT_EQ(obb_rotation_table(both)[0], obb_rotation_table(ObbConfig{both.angle_steps})[0]);
    ObbConfig too_many = tilted(12, 11), none = tilted(14, 1);
    too_many.angle_steps = 4;  // 9 + 120
    for (const ObbConfig& c : {too_many, none})
        try {
            obb_rotation_table(c);
            ADD_FAILURE() << "a table of " << 3 * (c.angle_steps - 1) + c.turn_steps * (c.tilt_steps - 1)
                          << " rotations accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("obb_tilt_steps give"), std::string::npos) << e.what();
        }
}

/// The largest |cosine| between `d` and an axis of any frame of `table` (1: one axis along `d`).
double best_alignment(const std::vector<Rotation>& table, const Vec3& d) {
    double best = std::max({std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)});
    for (const Rotation& m : table) {
        const Vec3 f = obb_rotate(m.data(), d);
        best = std::max({best, double(std::fabs(f.x)), double(std::fabs(f.y)), double(std::fabs(f.z))});
    }
    return best;
}

TEST(Obvh, TiltedFramesBringEveryDirectionNearABoxAxis) {
    const std::vector<Rotation> single = obb_rotation_table(ObbConfig{});
    const std::vector<Rotation> both = obb_rotation_table(tilted(12, 11));
    const Vec3 diagonal = glm::normalize(Vec3(1.0f, 1.0f, 1.0f));
    EXPECT_LT(best_alignment(single, diagonal), std::cos(0.5));  // 35 degrees off every axis
    EXPECT_GT(best_alignment(both, diagonal), std::cos(9.0 * M_PI / 180));
    Rng rng(7);
    double worst = 1.0;
    for (int i = 0; i < 2000; ++i) {
        const double z = 1.0 - 2.0 * rng.next(), phi = 2.0 * M_PI * rng.next(), ring = std::sqrt(1.0 - z * z);
        const Vec3 d(float(ring * std::cos(phi)), float(ring * std::sin(phi)), float(z));
        worst = std::min(worst, best_alignment(both, d));
    }
    EXPECT_GT(worst, std::cos(9.0 * M_PI / 180)) << "a direction more than 9 degrees off every frame's axes";
}

/// Every triangle of a subtree lies inside the box its parent holds for it, in the parent's frame
/// (the fit's boxes bound the same float rotation, so exactly). Spatial splits clip the
/// axis-aligned boxes to parts of triangles (`clipped`): only the oriented ones hold them whole.
void expect_boxes_contain_triangles(const ObvhAccel& a, const std::string& what, bool clipped = false) {
    const Bvh2View& v = a.view();
    std::vector<std::pair<uint32_t, uint32_t>> range(v.node_count);  // each node's triangles
    for (uint64_t i = v.node_count; i-- > 0;) {
        uint32_t lo = UINT32_MAX, hi = 0;
        for (int c = 0; c < 2; ++c) {
            const uint32_t k = v.nodes[i].child_count[c], ref = v.nodes[i].child_ref[c];
            if (k == kEmptyChild) continue;
            const auto r = k == 0 ? range[ref] : std::make_pair(ref, ref + k);
            lo = std::min(lo, r.first), hi = std::max(hi, r.second);
        }
        range[i] = {lo, hi};
    }
    int outside = 0;
    for (uint64_t i = 0; i < v.node_count; ++i) {
        const float* m = v.oriented(uint32_t(i)) ? v.rotation_table + 9 * v.rotations[i] : nullptr;
        if (!m && clipped) continue;
        for (int c = 0; c < 2; ++c) {
            const HwNode& n = v.nodes[i];
            if (n.child_count[c] == kEmptyChild) continue;
            const auto r = n.child_count[c] == 0 ? range[n.child_ref[c]]
                                                 : std::make_pair(n.child_ref[c], n.child_ref[c] + n.child_count[c]);
            for (uint32_t t = r.first; t < r.second; ++t)
                for (const float* p : {v.triangles[t].v0, v.triangles[t].v1, v.triangles[t].v2}) {
                    const Vec3 q = m ? obb_rotate(m, Vec3(p[0], p[1], p[2])) : Vec3(p[0], p[1], p[2]);
                    for (int ax = 0; ax < 3; ++ax) outside += q[ax] < n.lo(c, ax) || q[ax] > n.hi(c, ax);
                }
        }
    }
    EXPECT_EQ(outside, 0) << what;
}

TEST(Obvh, BoxesContainTheirTrianglesInEachFrame) {
    expect_boxes_contain_triangles(obvh(*build_named(test::random_soup(1, 1500), "obvh2", {{"obb_min_gain", 0.0}})),
                                   "soup");
    expect_boxes_contain_triangles(
        obvh(*build_named(test::random_soup(1, 1500), "obvh2", {{"obb_min_gain", 0.0}, {"obb_angle_steps", 1}, {"obb_turn_steps", 12}, {"obb_tilt_steps", 11}})),
        "soup, tilted frames");
    for (const char* name : {"rotated_walls", "hairball", "teapot_stadium"})
        for (const char* kind : {"obvh2", "obvh2:sbvh"})
            expect_boxes_contain_triangles(obvh(*build_named(test::procedural(name), kind)), std::string(name) + " " + kind,
                                           std::string(kind) == "obvh2:sbvh");
}

TEST(Obvh, AFitThatKeepsItsRotationsBoundsTheMovedTriangles) {
    // Thin triangles along random directions, then each drifted its own way: the refitted tree
    // with its build's rotations kept boxes every moved triangle in each node's frame.
    Rng rng(11);
    std::vector<Vec3> rest, moved;
    for (int i = 0; i < 800; ++i) {
        const Vec3 c = test::random_point(rng, Vec3(-4.0f), Vec3(4.0f));
        const Vec3 d = glm::normalize(test::random_point(rng, Vec3(-1.0f), Vec3(1.0f)) + Vec3(1e-3f));
        const Vec3 w = 0.01f * test::random_point(rng, Vec3(-1.0f), Vec3(1.0f));
        const Vec3 drift = 0.3f * test::random_point(rng, Vec3(-1.0f), Vec3(1.0f));
        for (const Vec3& p : {c - 0.5f * d, c + 0.5f * d, c + w}) rest.push_back(p), moved.push_back(p + drift);
    }
    const Scene a = test::make_scene(rest), b = test::make_scene(moved);
    const BuildTree built = build_binned_sah(a.triangles, BuildConfig{});
    ObbConfig obb;
    obb.min_gain = 0.0f;
    const AccelImage first = obvh2_image(built, a, BuildConfig{}, obb, "binned", 2);
    const std::vector<uint8_t> kept = obvh2_rotations(first);
    const AccelImage refit =
        obvh2_image(refit_build_tree(built, b.triangles), b, BuildConfig{}, obb, "binned", 2, &kept);
    const nlohmann::json& s = refit.stats["obvh2"];
    EXPECT_TRUE(s["rotations_kept"].get<bool>());
    EXPECT_GT(s["oriented_nodes"].get<uint64_t>(), 0u);
    EXPECT_LT(s["fit_node_frames"].get<uint64_t>(), first.stats["obvh2"]["fit_node_frames"].get<uint64_t>() / 4);
    // Each node keeps its rotation or drops it for the world's axes; none takes another.
    const std::vector<uint8_t> now = obvh2_rotations(refit);
    for (size_t i = 0; i < now.size(); ++i) EXPECT_TRUE(now[i] == kept[i] || now[i] == kNoRotation) << "node " << i;
    const ObvhAccel accel(refit, "kept refit");
    expect_boxes_contain_triangles(accel, "kept refit");
    EXPECT_GT(expect_structure_correct(accel, b, test::random_rays(b, test::hw_triangles(b), 5, 400), "kept"), 20);
}

TEST(Obvh, RotatedGeometryGetsOrientedNodesAndALowerSah) {
    const Scene& scene = test::procedural("rotated_walls");
    const auto a = build_named(scene, "obvh2");
    const nlohmann::json& s = a->image().stats["obvh2"];
    EXPECT_GT(s["oriented_fraction"].get<double>(), 0.05);
    EXPECT_LT(s["child_area_ratio"].get<double>(), 0.95);
    EXPECT_LT(a->image().stats["sah_cost"].get<double>(), a->image().stats["sah_cost_aabb"].get<double>());
    // The tree is bvh2's: the axis-aligned SAH cost is the binary BVH's.
    EXPECT_DOUBLE_EQ(a->image().stats["sah_cost_aabb"].get<double>(),
                     build_named(scene, "bvh2")->image().stats["sah_cost"].get<double>());
}

TEST(Obvh, WithoutOrientationsItWalksAsTheBinaryBvh) {
    const Scene& scene = test::procedural("teapot_stadium");
    const auto a = build_named(scene, "obvh2", {{"obb_min_gain", 1.0}});
    EXPECT_EQ(a->image().stats["obvh2"]["oriented_nodes"].get<uint64_t>(), 0u);
    const auto b = build_named(scene, "bvh2");
    for (const Ray& r : test::random_rays(scene, test::hw_triangles(scene), 3, 500))
        for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
            WorkCounts wa, wb;
            a->trace(r, mode, &wa);
            b->trace(r, mode, &wb);
            EXPECT_EQ(wa, wb);
        }
}

TEST(Obvh, AnOrientedStepAddsOneRotationAheadOfItsBoxTests) {
    const Scene& scene = test::procedural("rotated_walls");
    const auto a = build_named(scene, "obvh2");
    std::unique_ptr<Stepper> s = a->make_stepper();
    uint64_t rotations = 0;
    for (const Ray& r : test::random_rays(scene, test::hw_triangles(scene), 4, 300)) {
        s->begin(r, TraversalMode::closest_hit);
        while (!s->done()) {
            const StepPlan& p = s->plan();
            for (int i = 0; i < p.op_count; ++i)
                if (p.op[i].kind == OpKind::obb) {
                    EXPECT_EQ(p.op[i].count, 1u);
                    ASSERT_LT(i + 1, int(p.op_count));
                    EXPECT_EQ(p.op[i + 1].kind, OpKind::box);  // the rotation first: the tests need it
                }
            s->execute();
        }
        EXPECT_LE(s->work().obb_rotations, s->work().steps);
        rotations += s->work().obb_rotations;
    }
    EXPECT_GT(rotations, 0u);
}

/// A tessellated cube turned by table rotation `index` (world = m^T local) and its lattice rays
/// turned alike: faces, edges and vertices lie on an oriented node's box planes.
TEST(ObvhHardCases, FacesEdgesVerticesOfRotatedGeometryAndScales) {
    const std::vector<Vec3> unit = test::tessellated_cube(8);
    for (const bool two : {false, true})
    for (size_t index : {size_t(5), size_t(40), size_t(77)})
        for (const auto& [scale, offset] : std::vector<std::pair<float, float>>{{1.0f, 0.0f}, {1e12f, 0.0f},
                                                                              {1e-12f, 0.0f}, {1.0f, 1e6f}}) {
            const Rotation& m = obb_rotation_table(two ? tilted(12, 11) : ObbConfig{})[index];
            const Rotation mt{m[0], m[3], m[6], m[1], m[4], m[7], m[2], m[5], m[8]};
            std::vector<Vec3> soup;
            for (const Vec3& v : unit) soup.push_back(Vec3(offset) + obb_rotate(mt.data(), scale * v));
            const Scene scene = test::make_scene(soup);
            std::vector<Ray> rays;
            for (const Ray& r : test::lattice_rays(scale, Vec3(0.0f))) {
                Ray t = r;
                t.origin = Vec3(offset) + obb_rotate(mt.data(), r.origin);
                t.direction = obb_rotate(mt.data(), r.direction);
                rays.push_back(t);
            }
            const std::string what = std::string(two ? "tilted " : "") + "cube turned by rotation " +
                                     std::to_string(index) + " x " +
                                     std::to_string(scale) + " + " + std::to_string(offset);
            const auto a = build_named(scene, "obvh2", two ? nlohmann::json{{"obb_min_gain", 0.0}, {"obb_angle_steps", 1}, {"obb_turn_steps", 12}, {"obb_tilt_steps", 11}}
                                       : nlohmann::json{{"obb_min_gain", 0.0}});
            EXPECT_GT(a->image().stats["obvh2"]["oriented_nodes"].get<uint64_t>(), 0u) << what;
            EXPECT_GT(expect_structure_correct(*a, scene, rays, what), 300) << what;
        }
}

TEST(Obvh, CorruptImagesAreRefusedNamingTheCulprit) {
    const Scene scene = test::random_soup(2, 300);
    AccelOptions o;
    o.kind = "obvh2";
    const AccelImage good = build_accel(scene, o);
    auto refused = [&](const std::function<void(AccelImage&)>& corrupt, const std::string& expect) {
        AccelImage bad = good;
        corrupt(bad);
        try {
            load_accel(std::move(bad), "bad.rtt");
            ADD_FAILURE() << "accepted: " << expect;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(expect), std::string::npos) << e.what();
        }
    };
    refused([](AccelImage& i) { i.region("nodes").records<HwObbNode>()[0].rotation = 126; }, "names rotation 126");
    refused([](AccelImage& i) { i.params["rotations"][0][4] = 2.0; }, "rotation 0 has an entry");
    refused([](AccelImage& i) { i.params["rotations"][1] = nlohmann::json::array({1, 0}); }, "rotation 1 is not a 3x3");
    refused([](AccelImage& i) { i.params.erase("rotations"); }, "params.rotations");
    refused([](AccelImage& i) { i.region("nodes").records<HwObbNode>()[0].child_ref[0] = 0; }, "node 0 child 0");
    // Short stacks and reduced-precision boxes walk oriented nodes too (test_short_stack.cpp,
    // test_rp_boxes.cpp): the good image takes them.
    const auto a = load_accel(AccelImage(good), "good");
    StepOptions step;
    step.box_precision_bits = 8;
    step.short_stack_entries = 2;
    EXPECT_NE(a->make_stepper(step), nullptr);
}

}  // namespace
}  // namespace rtsim
