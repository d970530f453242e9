// Packets on the binary and the wide BVHs and the space-partitioning trees (Wald et al. 2001): every ray's closest hit equals single-ray
// traversal bit for bit and every any-hit ray agrees on occlusion, on the procedural scenes, an
// alpha-masked soup and the hard cases (rays from inside closed meshes, aimed at shared vertices,
// invalid rays); the packet stepper and the fused packet loop agree on hits, work and counts;
// the stepper's plans ask for exactly the packet's work; a packet of one ray, or of copies of one
// ray, does the single ray's work with every ray active in every step.
#include <gtest/gtest.h>

#include "structure_test_util.h"
#include "traces/accel/bvh2/bvh2.h"
#include "traces/common/error.h"

namespace rtsim {
namespace {

/// Packets of `lanes` consecutive rays: hits against single rays, stepper against fused loop,
/// plans against work. Returns the packets' counts.
PacketCounts check_packets(const Accel& accel, const std::vector<Ray>& rays, uint32_t lanes, TraversalMode mode,
                           const std::string& what, float split_below = 0.0f, const StepOptions& options = {}) {
    std::unique_ptr<PacketStepper> s = accel.make_packet_stepper(options);
    s->set_split_below(split_below);
    PacketCounts total;
    int diffs = 0;
    for (size_t first = 0; first < rays.size(); first += lanes) {
        const uint32_t n = uint32_t(std::min<size_t>(lanes, rays.size() - first));
        const std::vector<TraversalMode> modes(n, mode);
        std::vector<Hit> hits(n);
        std::vector<WorkCounts> work(n);
        PacketCounts fused;
        accel.trace_packet(&rays[first], modes.data(), n, hits.data(), work.data(), &fused, split_below, options);
        // The stepper, driven step by step: its plans' tests are the active rays' tests.
        s->begin_packet(&rays[first], modes.data(), n);
        uint64_t box = 0, obb = 0, tri = 0, alpha = 0, fetches = 0;
        while (!s->done()) {
            const StepPlan& p = s->plan();
            fetches += p.fetch_count;
            for (int i = 0; i < p.op_count; ++i)
                (p.op[i].kind == OpKind::box ? box : p.op[i].kind == OpKind::obb ? obb : tri) += p.op[i].count;
            const StepOutcome out = s->execute();
            for (int i = 0; i < out.op_count; ++i) alpha += out.op[i].count;
        }
        EXPECT_EQ(s->counts(), fused) << what;
        EXPECT_EQ(fetches, fused.node_steps + fused.leaf_steps) << what << ": one fetch per packet step";
        WorkCounts sum;
        for (uint32_t i = 0; i < n; ++i) {
            EXPECT_TRUE(test::same_hit(s->lane_hit(i), hits[i], TraversalMode::closest_hit)) << what;
            EXPECT_EQ(s->lane_work(i), work[i]) << what;
            sum.box_tests += work[i].box_tests, sum.tri_tests += work[i].tri_tests;
            sum.obb_rotations += work[i].obb_rotations;
            sum.anyhit_calls += work[i].anyhit_calls;
            const Hit single = accel.trace(rays[first + i], mode);
            if (!test::same_hit(hits[i], single, mode) && ++diffs <= 3)
                ADD_FAILURE() << what << ": ray " << first + i << " packet prim " << hits[i].prim << " t " << hits[i].t
                              << ", single prim " << single.prim << " t " << single.t;
        }
        EXPECT_EQ(box, sum.box_tests) << what;
        EXPECT_EQ(obb, sum.obb_rotations) << what;
        EXPECT_EQ(tri, sum.tri_tests) << what;
        EXPECT_EQ(alpha, sum.anyhit_calls) << what;
        total += fused;
    }
    EXPECT_EQ(diffs, 0) << what;
    return total;
}

/// Coherent rays: from one point outside the scene into a narrow cone, in pixel order, over
/// `span` of the scene's extent (1: all of it).
std::vector<Ray> camera_rays(const std::vector<HwTriangle>& tris, int n, uint64_t seed, float span = 1.0f) {
    Aabb bounds;
    for (const HwTriangle& t : tris)
        for (const float* v : {t.v0, t.v1, t.v2}) bounds.grow(Vec3(v[0], v[1], v[2]));
    const Vec3 c = 0.5f * (bounds.lo + bounds.hi), e = bounds.hi - bounds.lo;
    const Vec3 eye = c + Vec3(0.3f, 0.2f, 1.5f) * glm::length(e);
    Rng rng(seed);
    std::vector<Ray> rays;
    const int side = int(std::sqrt(float(n)));
    for (int y = 0; y < side; ++y)
        for (int x = 0; x < side; ++x) {
            const Vec3 target = c + (Vec3((x + rng.next()) / side, (y + rng.next()) / side, 0.5f) - 0.5f) * span * e;
            rays.push_back(test::make_ray(eye, target - eye));
        }
    return rays;
}

TEST(Packets, HitsEqualSingleRaysOnProceduralScenes) {
    for (const std::string name : {"cornell", "hairball", "teapot_stadium", "rotated_walls"}) {
        const Scene& scene = test::procedural(name);
        const std::unique_ptr<Accel> accel = test::bvh2_of(scene);
        const std::vector<HwTriangle> tris = test::hw_triangles(scene);
        const std::vector<Ray> random = test::random_rays(scene, tris, 7, 1024), camera = camera_rays(tris, 1024, 3);
        for (uint32_t lanes : {1u, 4u, 16u, 64u})
            for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
                const std::string what = name + " lanes " + std::to_string(lanes) + " mode " + std::to_string(int(mode));
                check_packets(*accel, random, lanes, mode, what + " random");
                const PacketCounts c = check_packets(*accel, camera, lanes, mode, what + " camera");
                // Coherent packets share most of their steps: far fewer node fetches than rays.
                if (lanes == 64 && mode == TraversalMode::closest_hit) {
                    uint64_t single_steps = 0;
                    for (const Ray& r : camera) {
                        WorkCounts w;
                        accel->trace(r, mode, &w);
                        single_steps += w.steps;
                    }
                    EXPECT_LT(c.node_steps * 4, single_steps) << what;
                }
            }
    }
}

TEST(Packets, TheHybridSplitsLowOccupancyPacketsIntoSingleRays) {
    // Benthin et al. 2012: after a split each ray walks alone with the single-ray rules, so its
    // hits stay the single ray's and the single-ray tail does a single ray's steps.
    for (const std::string name : {"cornell", "hairball"}) {
        const Scene& scene = test::procedural(name);
        const std::unique_ptr<Accel> accel = test::bvh2_of(scene);
        const std::vector<HwTriangle> tris = test::hw_triangles(scene);
        const std::vector<Ray> random = test::random_rays(scene, tris, 29, 1024), camera = camera_rays(tris, 1024, 5);
        for (float split : {0.25f, 0.5f, 1.0f})
            for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
                const std::string what = name + " split " + std::to_string(split);
                const PacketCounts r = check_packets(*accel, random, 16, mode, what + " random", split);
                EXPECT_GT(r.splits, 0u) << what;
                EXPECT_GT(r.split_steps, 0u) << what;
                check_packets(*accel, camera, 16, mode, what + " camera", split);
            }
        // Without a threshold nothing splits; with one, steps hold fewer rays on average (the
        // single-ray tail runs one ray per step).
        const PacketCounts none = check_packets(*accel, random, 16, TraversalMode::closest_hit, name, 0.0f);
        const PacketCounts half = check_packets(*accel, random, 16, TraversalMode::closest_hit, name, 0.5f);
        EXPECT_EQ(none.splits, 0u);
        EXPECT_LT(half.active_rays * (none.node_steps + none.leaf_steps), none.active_rays * (half.node_steps + half.leaf_steps));
    }
}

TEST(Packets, HardCasesAndAlphaMasks) {
    // An alpha-masked soup with coincident triangles, a closed sphere from inside, invalid rays.
    const Scene soup = test::random_soup(5, 400);
    const std::unique_ptr<Accel> a = test::bvh2_of(soup);
    std::vector<Ray> rays = test::random_rays(soup, test::hw_triangles(soup), 11, 512);
    rays[3].tmin = std::numeric_limits<float>::quiet_NaN();
    rays[17].direction = Vec3(0.0f);
    for (uint32_t lanes : {4u, 16u, 64u})
        for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit})
            check_packets(*a, rays, lanes, mode, "soup " + std::to_string(lanes));
    const std::vector<Vec3> sphere = test::icosphere(3);
    const std::unique_ptr<Accel> s = test::bvh2_of(test::make_scene(sphere));
    std::vector<Ray> inside;
    for (size_t t = 0; t < sphere.size(); ++t) inside.push_back(test::make_ray(Vec3(0.0f), sphere[t]));
    for (uint32_t lanes : {4u, 16u, 64u}) check_packets(*s, inside, lanes, TraversalMode::closest_hit, "sphere");
    std::unique_ptr<PacketStepper> st = s->make_packet_stepper();
    const Ray bad = test::make_ray(Vec3(0.0f), Vec3(0.0f));
    const TraversalMode m = TraversalMode::closest_hit;
    st->begin_packet(&bad, &m, 1);
    EXPECT_TRUE(st->done());  // an invalid ray alone: no step at all
    EXPECT_EQ(st->counts().node_steps, 0u);
}

TEST(Packets, CopiesOfOneRayDoItsSingleRayWorkFullyActive) {
    const Scene& scene = test::procedural("hairball");
    const std::unique_ptr<Accel> accel = test::bvh2_of(scene);
    const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), 19, 64);
    for (const Ray& r : rays) {
        if (!ray_is_valid(r)) continue;
        WorkCounts single;
        accel->trace(r, TraversalMode::closest_hit, &single);
        const std::vector<Ray> same(16, r);
        const std::vector<TraversalMode> modes(16, TraversalMode::closest_hit);
        std::vector<WorkCounts> work(16);
        PacketCounts c;
        accel->trace_packet(same.data(), modes.data(), 16, nullptr, work.data(), &c);
        for (const WorkCounts& w : work) EXPECT_EQ(w, single);
        EXPECT_EQ(c.node_steps, single.steps);
        EXPECT_EQ(c.active_rays, 16 * (c.node_steps + c.leaf_steps));  // occupancy exactly 1
    }
}

/// The wide kinds with a packet kernel, every codec and child order.
const char* const kWideKinds[] = {"bvh4", "bvh6", "bvh8", "cwbvh6", "cwbvh8", "bvh8_octant", "cwbvh8_octant"};

std::unique_ptr<Accel> accel_of(const Scene& scene, const std::string& kind) {
    AccelOptions o;
    o.kind = kind;
    return load_accel(build_accel(scene, o), "test " + kind);
}

TEST(Packets, WideBvhsHitsEqualSingleRaysAndStepperEqualsFusedLoop) {
    // Packets on 4- and 8-wide nodes (Dammertz et al. 2008, Ernst & Greiner 2008), with and
    // without the hybrid's split: the same checks as the binary BVH's.
    for (const std::string name : {"cornell", "hairball"}) {
        const Scene& scene = test::procedural(name);
        const std::vector<HwTriangle> tris = test::hw_triangles(scene);
        const std::vector<Ray> random = test::random_rays(scene, tris, 13, 512), camera = camera_rays(tris, 576, 7);
        for (const char* kind : kWideKinds) {
            const std::unique_ptr<Accel> accel = accel_of(scene, kind);
            ASSERT_TRUE(accel->capabilities().packet_kernel) << kind;
            for (uint32_t lanes : {1u, 8u, 16u, 64u})
                for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
                    const std::string what = name + " " + kind + " lanes " + std::to_string(lanes) + " mode " +
                                             std::to_string(int(mode));
                    check_packets(*accel, random, lanes, mode, what + " random");
                    const PacketCounts c = check_packets(*accel, camera, lanes, mode, what + " camera");
                    if (lanes == 64 && mode == TraversalMode::closest_hit) {
                        uint64_t single_steps = 0;
                        for (const Ray& r : camera) {
                            WorkCounts w;
                            accel->trace(r, mode, &w);
                            single_steps += w.steps;
                        }
                        // Coherent packets share steps (fewer per ray on wide nodes than on binary ones).
                        EXPECT_LT(c.node_steps * 3, single_steps) << what;
                    }
                }
            for (float split : {0.25f, 0.5f}) {
                const PacketCounts r =
                    check_packets(*accel, random, 16, TraversalMode::closest_hit, name + " " + kind + " split", split);
                EXPECT_GT(r.splits, 0u) << kind;
                check_packets(*accel, camera, 16, TraversalMode::any_hit, name + " " + kind + " split camera", split);
            }
        }
    }
}

TEST(Packets, WideBvhsCopiesOfOneRayDoItsSingleRayWorkFullyActive) {
    const Scene& scene = test::procedural("hairball");
    const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), 23, 48);
    for (const char* kind : kWideKinds) {
        const std::unique_ptr<Accel> accel = accel_of(scene, kind);
        for (const Ray& r : rays) {
            if (!ray_is_valid(r)) continue;
            WorkCounts single;
            const Hit h = accel->trace(r, TraversalMode::closest_hit, &single);
            const std::vector<Ray> same(16, r);
            const std::vector<TraversalMode> modes(16, TraversalMode::closest_hit);
            std::vector<WorkCounts> work(16);
            std::vector<Hit> hits(16);
            PacketCounts c;
            accel->trace_packet(same.data(), modes.data(), 16, hits.data(), work.data(), &c);
            for (uint32_t i = 0; i < 16; ++i) {
                EXPECT_EQ(work[i], single) << kind;
                EXPECT_TRUE(test::same_hit(hits[i], h, TraversalMode::closest_hit)) << kind;
            }
            EXPECT_EQ(c.node_steps, single.steps) << kind;
            EXPECT_EQ(c.active_rays, 16 * (c.node_steps + c.leaf_steps)) << kind;
        }
    }
}

/// Packets of 16 with the hybrid's split rays walking on their own lanes (SplitWalks::lanes),
/// the walkers stepped round robin as a unit's lanes would: each ray's hit and work, and the
/// packet's counts, are the serial walk's (the fused loop's).
void check_lane_walks(const Accel& accel, const std::vector<Ray>& rays, TraversalMode mode, float split,
                      const std::string& what, bool expect_split, const StepOptions& options = {}) {
    std::unique_ptr<PacketStepper> s = accel.make_packet_stepper(options);
    s->set_split_below(split);
    s->set_split_walks(SplitWalks::lanes);
    uint64_t launched = 0;
    for (size_t first = 0; first + 16 <= rays.size(); first += 16) {
        const std::vector<TraversalMode> modes(16, mode);
        std::vector<Hit> hits(16);
        std::vector<WorkCounts> work(16);
        PacketCounts fused;
        accel.trace_packet(&rays[first], modes.data(), 16, hits.data(), work.data(), &fused, split, options);
        s->begin_packet(&rays[first], modes.data(), 16);
        while (!s->done()) s->execute();
        for (LaneMask walking = s->split_lanes(); walking;) {
            launched += lane_count(walking);
            for_each_lane(walking, [&](uint32_t r) {
                Stepper& w = s->lane_walker(r);
                EXPECT_GT(w.plan().fetch_count, 0) << what;  // a walker's step fetches its node or leaf
                w.execute();
                if (w.done()) walking &= ~lane_bit(r);
            });
        }
        EXPECT_EQ(s->counts(), fused) << what;
        for (uint32_t i = 0; i < 16; ++i) {
            EXPECT_TRUE(test::same_hit(s->lane_hit(i), hits[i], TraversalMode::closest_hit)) << what << " ray " << i;
            EXPECT_EQ(s->lane_work(i), work[i]) << what << " ray " << i;
        }
    }
    if (expect_split) {
        EXPECT_GT(launched, 0u) << what;
    }
}

TEST(Packets, SplitRaysOnTheirOwnLanesWalkAsTheSerialHybrid) {
    for (const std::string name : {"cornell", "hairball"}) {
        const Scene& scene = test::procedural(name);
        const std::vector<HwTriangle> tris = test::hw_triangles(scene);
        const std::vector<Ray> random = test::random_rays(scene, tris, 31, 512), camera = camera_rays(tris, 576, 9);
        for (const std::string kind : {"bvh2", "bvh4", "bvh8", "cwbvh8", "cwbvh8_octant"}) {
            const std::unique_ptr<Accel> accel = accel_of(scene, kind);
            for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit})
                for (float split : {0.25f, 0.5f, 1.0f}) {
                    const std::string what = name + " " + kind + " split " + std::to_string(split);
                    check_lane_walks(*accel, random, mode, split, what + " random", true);
                    check_lane_walks(*accel, camera, mode, split, what + " camera", false);
                }
        }
    }
}

TEST(Packets, AnyHitPacketsWalkInTheRunsChildOrder) {
    // traversal.anyhit_order on packets: an all-any-hit step takes the order's child first (the
    // boxes', the same for every ray), so a packet of one ray, or of copies of one, does the
    // single-ray stepper's work in that order; stepper and fused loop agree; occlusion never changes.
    const Scene& scene = test::procedural("hairball");
    const std::vector<HwTriangle> tris = test::hw_triangles(scene);
    const std::vector<Ray> random = test::random_rays(scene, tris, 41, 384), camera = camera_rays(tris, 576, 11);
    for (const std::string kind : {"bvh2", "gkbvh", "bvh4", "bvh8", "cwbvh8", "cwbvh8_octant"}) {
        const std::unique_ptr<Accel> accel = accel_of(scene, kind);
        ASSERT_TRUE(accel->capabilities().anyhit_order) << kind;
        uint64_t nearest_steps = 0, reordered_steps = 0;
        for (AnyHitOrder order : {AnyHitOrder::largest_box, AnyHitOrder::fixed}) {
            StepOptions options;
            options.anyhit_order = order;
            const std::string what = kind + " order " + std::to_string(int(order));
            for (uint32_t lanes : {1u, 16u, 64u}) {
                check_packets(*accel, random, lanes, TraversalMode::any_hit, what + " random", 0.0f, options);
                check_packets(*accel, camera, lanes, TraversalMode::any_hit, what + " camera", 0.0f, options);
            }
            check_packets(*accel, random, 16, TraversalMode::any_hit, what + " split", 0.5f, options);
            check_lane_walks(*accel, random, TraversalMode::any_hit, 0.5f, what + " lane walks", true, options);
            for (size_t i = 0; i < 96; ++i) {
                const Ray& r = random[i];
                WorkCounts single, near;
                accel->trace(r, TraversalMode::any_hit, &single, options);
                accel->trace(r, TraversalMode::any_hit, &near);
                const std::vector<Ray> same(16, r);
                const std::vector<TraversalMode> modes(16, TraversalMode::any_hit);
                std::vector<WorkCounts> work(16);
                accel->trace_packet(same.data(), modes.data(), 16, nullptr, work.data(), nullptr, 0.0f, options);
                for (const WorkCounts& w : work) EXPECT_EQ(w, single) << what << " ray " << i;
                if (order == AnyHitOrder::largest_box) nearest_steps += near.steps, reordered_steps += single.steps;
            }
            // A closest-hit ray among any-hit rays keeps its nearest-first walk and its closest hit.
            std::vector<TraversalMode> mixed(16, TraversalMode::any_hit);
            mixed[0] = mixed[7] = TraversalMode::closest_hit;
            std::vector<Hit> hits(16);
            accel->trace_packet(camera.data(), mixed.data(), 16, hits.data(), nullptr, nullptr, 0.0f, options);
            for (uint32_t i : {0u, 7u})
                EXPECT_TRUE(test::same_hit(hits[i], accel->trace(camera[i], TraversalMode::closest_hit),
                                           TraversalMode::closest_hit))
                    << what;
        }
        EXPECT_NE(nearest_steps, reordered_steps) << kind << ": the order changed no walk (a vacuous test)";
    }
}

TEST(Packets, OrientedNodesHitsEqualSingleRaysAndStepperEqualsFusedLoop) {
    // Packets on the oriented BVH (obvh2): each active ray rotated into an oriented node's frame,
    // as a single ray is; the same checks as the binary BVH's, the hybrid's split and its lane
    // walks included, on scenes whose strands and walls lie diagonally.
    for (const std::string name : {"hairball", "rotated_walls"}) {
        const Scene& scene = test::procedural(name);
        const std::vector<HwTriangle> tris = test::hw_triangles(scene);
        const std::vector<Ray> random = test::random_rays(scene, tris, 17, 512), camera = camera_rays(tris, 576, 5);
        const std::unique_ptr<Accel> accel = accel_of(scene, "obvh2");
        ASSERT_TRUE(accel->capabilities().packet_kernel);
        uint64_t rotations = 0;
        for (uint32_t lanes : {1u, 8u, 16u, 64u})
            for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
                const std::string what = name + " obvh2 lanes " + std::to_string(lanes) + " mode " +
                                         std::to_string(int(mode));
                check_packets(*accel, random, lanes, mode, what + " random");
                check_packets(*accel, camera, lanes, mode, what + " camera");
            }
        for (float split : {0.25f, 0.5f}) {
            const PacketCounts r =
                check_packets(*accel, random, 16, TraversalMode::closest_hit, name + " obvh2 split", split);
            EXPECT_GT(r.splits, 0u) << name;
            check_lane_walks(*accel, random, TraversalMode::closest_hit, split, name + " obvh2 lane walks", true);
        }
        for (size_t i = 0; i < 64; ++i) {  // copies of one ray: its single-ray work, rotations included
            const Ray& r = random[i];
            if (!ray_is_valid(r)) continue;
            WorkCounts single;
            accel->trace(r, TraversalMode::closest_hit, &single);
            rotations += single.obb_rotations;
            const std::vector<Ray> same(16, r);
            const std::vector<TraversalMode> modes(16, TraversalMode::closest_hit);
            std::vector<WorkCounts> work(16);
            accel->trace_packet(same.data(), modes.data(), 16, nullptr, work.data(), nullptr, 0.0f);
            for (const WorkCounts& w : work) EXPECT_EQ(w, single) << name << " ray " << i;
        }
        EXPECT_GT(rotations, 0u) << name << ": no oriented node was stepped";
    }
}

TEST(Packets, PacketsOfMoreThan64RaysAreRefused) {
    const Scene& scene = test::procedural("cornell");
    const Ray r = test::make_ray(Vec3(0.0f), Vec3(0.0f, 0.0f, 1.0f));
    const TraversalMode m = TraversalMode::closest_hit;
    for (const std::string kind : {"bvh2", "bvh4", "kdtree", "octree", "grid"}) {
        std::unique_ptr<PacketStepper> s = accel_of(scene, kind)->make_packet_stepper();
        std::vector<Ray> many(65, r);
        std::vector<TraversalMode> modes(65, m);
        EXPECT_THROW(s->begin_packet(many.data(), modes.data(), 65), Error);
    }
}

/// The space-partitioning structures with a packet kernel (cell_packet.h, grid_packet.h).
const char* const kCellKinds[] = {"kdtree", "bih", "bkd", "octree", "grid"};

/// Packets of `lanes` consecutive rays on a space-partitioning tree: each ray's hit against the
/// single ray's, the plans' operations against the rays' work, and (with a mailbox) the work
/// counted back equal to the work without one. Returns the packets' counts.
PacketCounts check_cell_packets(const Accel& accel, const std::vector<Ray>& rays, uint32_t lanes, TraversalMode mode,
                                const std::string& what, float split_below = 0.0f, uint32_t mailbox = 0) {
    StepOptions options;
    options.mailbox_entries = mailbox;
    std::unique_ptr<PacketStepper> s = accel.make_packet_stepper(options);
    s->set_split_below(split_below);
    PacketCounts total;
    int diffs = 0;
    for (size_t first = 0; first < rays.size(); first += lanes) {
        const uint32_t n = uint32_t(std::min<size_t>(lanes, rays.size() - first));
        const std::vector<TraversalMode> modes(n, mode);
        std::vector<Hit> hits(n);
        std::vector<WorkCounts> work(n);
        PacketCounts plain;
        accel.trace_packet(&rays[first], modes.data(), n, hits.data(), work.data(), &plain, split_below);
        s->begin_packet(&rays[first], modes.data(), n);
        uint64_t ops[kOpKindCount] = {}, alpha = 0, steps = 0;
        while (!s->done()) {
            const StepPlan& p = s->plan();
            EXPECT_GT(s->active(), 0u) << what;
            ++steps;
            for (int i = 0; i < p.op_count; ++i) ops[size_t(p.op[i].kind)] += p.op[i].count;
            const StepOutcome out = s->execute();
            for (int i = 0; i < out.op_count; ++i) alpha += out.op[i].count;
        }
        EXPECT_EQ(steps, s->counts().node_steps + s->counts().leaf_steps) << what;
        if (mailbox == 0) EXPECT_EQ(s->counts(), plain) << what;
        WorkCounts sum;
        for (uint32_t i = 0; i < n; ++i) {
            const WorkCounts& w = s->lane_work(i);
            EXPECT_EQ(w.traced(), work[i]) << what << ": a mailbox skips only retests";
            EXPECT_TRUE(test::same_hit(s->lane_hit(i), hits[i], TraversalMode::closest_hit)) << what;
            sum.box_tests += w.box_tests, sum.plane_tests += w.plane_tests, sum.tri_tests += w.tri_tests;
            sum.anyhit_calls += w.anyhit_calls;
            const Hit single = accel.trace(rays[first + i], mode);
            if (!test::same_hit(hits[i], single, mode) && ++diffs <= 3)
                ADD_FAILURE() << what << ": ray " << first + i << " packet prim " << hits[i].prim << " t " << hits[i].t
                              << ", single prim " << single.prim << " t " << single.t;
        }
        EXPECT_EQ(ops[size_t(OpKind::box)], sum.box_tests) << what;
        EXPECT_EQ(ops[size_t(OpKind::plane)], sum.plane_tests) << what;
        EXPECT_EQ(ops[size_t(OpKind::triangle)], sum.tri_tests) << what;
        EXPECT_EQ(alpha, sum.anyhit_calls) << what;
        total += s->counts();
    }
    EXPECT_EQ(diffs, 0) << what;
    return total;
}

TEST(Packets, CellTreesHitsEqualSingleRays) {
    // Packets on the kd-tree (Wald et al. 2001's own structure), the BIH and the octree, with
    // and without mailboxes and the hybrid's split.
    for (const std::string name : {"cornell", "hairball", "teapot_stadium"}) {
        const Scene& scene = test::procedural(name);
        const std::vector<HwTriangle> tris = test::hw_triangles(scene);
        const std::vector<Ray> random = test::random_rays(scene, tris, 37, 512), camera = camera_rays(tris, 576, 11);
        for (const char* kind : kCellKinds) {
            const std::unique_ptr<Accel> accel = accel_of(scene, kind);
            ASSERT_TRUE(accel->capabilities().packet_kernel) << kind;
            for (uint32_t lanes : {1u, 8u, 16u, 64u})
                for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
                    const std::string what = name + " " + kind + " lanes " + std::to_string(lanes) + " mode " +
                                             std::to_string(int(mode));
                    check_cell_packets(*accel, random, lanes, mode, what + " random");
                    const PacketCounts c = check_cell_packets(*accel, camera, lanes, mode, what + " camera");
                    check_cell_packets(*accel, camera, lanes, mode, what + " camera mailbox", 0.0f, 8);
                    if (lanes == 64 && mode == TraversalMode::closest_hit) {
                        // Rays closer together than the cells are wide share their fetches.
                        const std::vector<Ray> bundle = camera_rays(tris, 64 * 9, 17, 0.05f);
                        uint64_t single_steps = 0;
                        for (const Ray& r : bundle) {
                            WorkCounts w;
                            accel->trace(r, mode, &w);
                            single_steps += w.steps;
                        }
                        const PacketCounts b = check_cell_packets(*accel, bundle, lanes, mode, what + " bundle");
                        EXPECT_LT(b.node_steps * 4, single_steps) << what;
                        EXPECT_LT(c.node_steps, single_steps + camera.size()) << what;
                    }
                }
            for (float split : {0.25f, 0.5f}) {
                const PacketCounts r =
                    check_cell_packets(*accel, random, 16, TraversalMode::closest_hit, name + " " + kind + " split", split);
                EXPECT_GT(r.splits, 0u) << kind;
                EXPECT_GT(r.split_steps, 0u) << kind;
                check_cell_packets(*accel, camera, 16, TraversalMode::any_hit, name + " " + kind + " split camera", split, 8);
            }
        }
    }
}

TEST(Packets, CellTreesCopiesOfOneRayDoItsSingleRayWorkFullyActive) {
    const Scene& scene = test::procedural("hairball");
    const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), 41, 48);
    for (const char* kind : kCellKinds)
        for (uint32_t mailbox : {0u, 8u}) {
            const std::unique_ptr<Accel> accel = accel_of(scene, kind);
            StepOptions options;
            options.mailbox_entries = mailbox;
            std::unique_ptr<PacketStepper> s = accel->make_packet_stepper(options);
            for (const Ray& r : rays) {
                if (!ray_is_valid(r)) continue;
                WorkCounts single;
                const Hit h = accel->trace(r, TraversalMode::closest_hit, &single, options);
                const std::vector<Ray> same(16, r);
                const std::vector<TraversalMode> modes(16, TraversalMode::closest_hit);
                s->begin_packet(same.data(), modes.data(), 16);
                while (!s->done()) s->execute();
                for (uint32_t i = 0; i < 16; ++i) {
                    EXPECT_EQ(s->lane_work(i), single) << kind;
                    EXPECT_TRUE(test::same_hit(s->lane_hit(i), h, TraversalMode::closest_hit)) << kind;
                }
                EXPECT_EQ(s->counts().active_rays, 16 * (s->counts().node_steps + s->counts().leaf_steps)) << kind;
            }
        }
}

TEST(Packets, CellTreesSplitRaysOnTheirOwnLanesWalkAsTheSerialHybrid) {
    for (const std::string name : {"cornell", "hairball"}) {
        const Scene& scene = test::procedural(name);
        const std::vector<HwTriangle> tris = test::hw_triangles(scene);
        const std::vector<Ray> random = test::random_rays(scene, tris, 43, 512), camera = camera_rays(tris, 576, 13);
        for (const char* kind : kCellKinds) {
            const std::unique_ptr<Accel> accel = accel_of(scene, kind);
            for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit})
                for (float split : {0.25f, 1.0f}) {
                    const std::string what = name + " " + kind + " split " + std::to_string(split);
                    check_lane_walks(*accel, random, mode, split, what + " random", true);
                    check_lane_walks(*accel, camera, mode, split, what + " camera", false);
                }
        }
    }
}

TEST(Packets, CellTreesHardCases) {
    // Rays from inside a closed sphere, aimed along the axes through shared vertices, invalid rays.
    const std::vector<Vec3> sphere = test::icosphere(3);
    const Scene scene = test::make_scene(sphere);
    std::vector<Ray> rays;
    for (size_t t = 0; t < sphere.size(); ++t) rays.push_back(test::make_ray(Vec3(0.0f), sphere[t]));
    for (int a = 0; a < 3; ++a)
        for (float s : {-1.0f, 1.0f}) {
            Vec3 d(0.0f);
            d[a] = s;
            rays.push_back(test::make_ray(Vec3(0.0f), d));
        }
    rays[5].tmin = std::numeric_limits<float>::quiet_NaN();
    rays[9].direction = Vec3(0.0f);
    for (const char* kind : kCellKinds) {
        const std::unique_ptr<Accel> accel = accel_of(scene, kind);
        for (uint32_t lanes : {4u, 16u, 64u})
            for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit})
                check_cell_packets(*accel, rays, lanes, mode, std::string("sphere ") + kind, 0.0f, 8);
        std::unique_ptr<PacketStepper> st = accel->make_packet_stepper();
        const Ray bad = test::make_ray(Vec3(0.0f), Vec3(0.0f));
        const TraversalMode m = TraversalMode::closest_hit;
        st->begin_packet(&bad, &m, 1);
        EXPECT_TRUE(st->done()) << kind;  // an invalid ray alone: no step at all
    }
}

}  // namespace
}  // namespace rtsim
