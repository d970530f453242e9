// Compressed wide BVHs: quantised boxes contain the exact ones (a property test over random
// boxes with huge, tiny, degenerate and negative coordinates), the compressed trees have the
// topology of their fp32 twins so the extra work is quantisation's (and never less on rays that
// miss, whose visits do not depend on the order), extreme coordinates trace identically, and
// validation refuses corrupt images by name.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>

#include "accel_test_util.h"
#include "traces/accel/cwbvh/cwbvh.h"
#include "traces/common/error.h"

namespace rtsim {
namespace {

/// A coordinate of random magnitude: sign, exponent from 2^-120 to 2^120, mantissa; sometimes 0.
float random_coordinate(Rng& rng) {
    if (rng.next() < 0.05f) return rng.next() < 0.5f ? 0.0f : -0.0f;
    const float m = 1.0f + rng.next();
    const int e = int(rng.next() * 240.0f) - 120;
    return (rng.next() < 0.5f ? -1.0f : 1.0f) * std::ldexp(m, e);
}

TEST(Quantize, DecodedBoxesContainTheExactOnesAndAreTight) {
    Rng rng(2024);
    long boxes = 0, loose_steps = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        // A node box from two random corners (per axis: random, degenerate, or a tiny extent).
        Aabb node;
        for (int a = 0; a < 3; ++a) {
            float x = random_coordinate(rng), y = random_coordinate(rng);
            const float kind = rng.next();
            if (kind < 0.1f) y = x;                                      // degenerate axis
            else if (kind < 0.2f) y = std::nextafter(x, INFINITY);       // one ulp wide
            else if (kind < 0.3f) y = x + std::fabs(x) * 1e-3f + 1e-30f;  // tiny relative extent
            node.lo[a] = std::min(x, y);
            node.hi[a] = std::max(x, y);
        }
        const QuantFrame f = make_quant_frame(node);
        for (int a = 0; a < 3; ++a) {
            ASSERT_GE(quant_decode(f.p[a], f.e[a], 255), node.hi[a]);
            if (f.e[a] > 1) {
                ASSERT_LT(quant_decode(f.p[a], uint8_t(f.e[a] - 1), 255), node.hi[a]);  // the smallest
            }
        }
        for (int c = 0; c < 8; ++c) {  // child boxes inside the node, some on its faces
            for (int a = 0; a < 3; ++a) {
                auto inside = [&] {
                    const float t = rng.next();
                    if (t < 0.1f) return node.lo[a];
                    if (t < 0.2f) return node.hi[a];
                    const float v = float(double(node.lo[a]) + double(t) * (double(node.hi[a]) - double(node.lo[a])));
                    return std::min(std::max(v, node.lo[a]), node.hi[a]);
                };
                float lo = inside(), hi = inside();
                if (lo > hi) std::swap(lo, hi);
                const uint8_t ql = quantize_lo(f, a, lo), qh = quantize_hi(f, a, hi);
                ASSERT_LE(quant_decode(f.p[a], f.e[a], ql), lo) << "lo " << lo << " axis " << a;
                ASSERT_GE(quant_decode(f.p[a], f.e[a], qh), hi) << "hi " << hi << " axis " << a;
                // Tight: one step further in would cut into the exact box.
                if (ql < 255) {
                    ASSERT_GT(quant_decode(f.p[a], f.e[a], ql + 1u), lo);
                }
                if (qh > 0) {
                    ASSERT_LT(quant_decode(f.p[a], f.e[a], qh - 1u), hi);
                }
                loose_steps += qh - ql;
                ++boxes;
            }
        }
    }
    EXPECT_EQ(boxes, 20000L * 8 * 3);
    EXPECT_GT(loose_steps, 0);
}

TEST(Quantize, BoundsOfANodeQuantiseLikeTheScalarRule) {
    // quantize_bounds (several bounds per SIMD operation, the node builder's) against
    // quantize_lo / quantize_hi, on frames of every magnitude and bounds on and near their ends.
    Rng rng(77);
    long compared = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        Aabb node;
        for (int a = 0; a < 3; ++a) {
            float x = random_coordinate(rng), y = random_coordinate(rng);
            if (rng.next() < 0.1f) y = std::nextafter(x, INFINITY);
            node.lo[a] = std::min(x, y);
            node.hi[a] = std::max(x, y);
        }
        const QuantFrame f = make_quant_frame(node);
        const uint32_t count = 1 + uint32_t(rng.next() * 8.0f) % 8;
        for (int a = 0; a < 3; ++a) {
            float lo[8], hi[8];
            for (uint32_t i = 0; i < count; ++i) {
                auto inside = [&] {
                    const float t = rng.next();
                    if (t < 0.15f) return node.lo[a];
                    if (t < 0.3f) return node.hi[a];
                    const double v = double(node.lo[a]) + double(t) * (double(node.hi[a]) - double(node.lo[a]));
                    return std::min(std::max(float(v), node.lo[a]), node.hi[a]);
                };
                lo[i] = inside(), hi[i] = inside();
                if (lo[i] > hi[i]) std::swap(lo[i], hi[i]);
            }
            uint8_t q_lo[8], q_hi[8];
            quantize_bounds(f, a, lo, hi, count, q_lo, q_hi);
            for (uint32_t i = 0; i < count; ++i, ++compared) {
                ASSERT_EQ(q_lo[i], quantize_lo(f, a, lo[i])) << "lo " << lo[i] << " trial " << trial;
                ASSERT_EQ(q_hi[i], quantize_hi(f, a, hi[i])) << "hi " << hi[i] << " trial " << trial;
            }
        }
    }
    EXPECT_GT(compared, 200000);
}

TEST(Cwbvh, SameTopologyAsTheFp32TwinAndNeverLessWorkOnMisses) {
    const Scene scene = test::random_soup(41, 4000);
    for (const auto& [fp32, cw] : {std::pair<std::string, std::string>{"bvh8", "cwbvh8"}, {"bvh6", "cwbvh6"}}) {
        const auto a = test::build_kind(scene, fp32), b = test::build_kind(scene, cw);
        // Same collapse, same order: the same nodes and the same triangle records, byte for byte.
        EXPECT_EQ(a->image().region("nodes").count, b->image().region("nodes").count);
        const Region &ta = test::triangles_of(*a), &tb = test::triangles_of(*b);
        ASSERT_EQ(ta.size_bytes(), tb.size_bytes());
        EXPECT_EQ(std::memcmp(ta.bytes.data(), tb.bytes.data(), ta.size_bytes()), 0);
        // The same tree's cost with exact boxes; the quantised boxes cost more (SahCostCounts...).
        EXPECT_EQ(a->image().stats["sah_cost"], b->image().stats["sah_cost_exact_boxes"]);
        EXPECT_GT(double(b->image().stats["sah_cost"]), double(a->image().stats["sah_cost"]));
        Rng rng(7);
        uint64_t misses = 0, steps[2] = {}, tris[2] = {}, all_steps[2] = {}, all_tris[2] = {};
        for (int i = 0; i < 20000; ++i) {
            const Ray r = test::random_ray(rng, scene.bounds, ta.records<HwTriangle>(), ta.count);
            WorkCounts wa, wb;
            const Hit ha = a->trace(r, TraversalMode::closest_hit, &wa), hb = b->trace(r, TraversalMode::closest_hit, &wb);
            ASSERT_TRUE(test::same_hit(ha, hb)) << cw << " ray " << i;
            all_steps[0] += wa.steps, all_steps[1] += wb.steps, all_tris[0] += wa.tri_tests, all_tris[1] += wb.tri_tests;
            if (ha.valid() || !ray_is_valid(r)) continue;
            // A miss visits every box it crosses, in any order: the decoded boxes contain the
            // exact ones, so the compressed tree visits a superset.
            ++misses;
            EXPECT_GE(wb.steps, wa.steps) << cw << " ray " << i;
            EXPECT_GE(wb.tri_tests, wa.tri_tests) << cw << " ray " << i;
            steps[0] += wa.steps, steps[1] += wb.steps, tris[0] += wa.tri_tests, tris[1] += wb.tri_tests;
        }
        EXPECT_GT(misses, 2000u);
        EXPECT_GT(all_tris[1], all_tris[0]);  // quantisation does cost something
        std::printf("[ quantise ] %s vs %s, 20000 rays: steps %+.2f%%, triangle tests %+.2f%% (misses only: "
                    "%+.2f%%, %+.2f%%)\n",
                    cw.c_str(), fp32.c_str(), 100.0 * (double(all_steps[1]) / double(all_steps[0]) - 1),
                    100.0 * (double(all_tris[1]) / double(all_tris[0]) - 1), 100.0 * (double(steps[1]) / double(steps[0]) - 1),
                    100.0 * (double(tris[1]) / double(tris[0]) - 1));
    }
}

TEST(Cwbvh, ExtremeCoordinatesTraceLikeTheBinaryBvh) {
    // Scenes scaled by 2^60 and 2^-60 (the watertight test's products stay finite and normal in
    // float up to about 2^63 and down to 2^-63), each with a cluster a million times smaller,
    // shifted off the origin: frames with extreme exponents at both ends.
    for (const float scale : {0x1p60f, 0x1p-60f, 1.0f}) {
        std::vector<Vec3> soup = test::icosphere(2);
        const std::vector<Vec3> cube = test::tessellated_cube(3);
        for (const Vec3& v : cube) soup.push_back(v * 1e-6f + Vec3(3.0f, -2.0f, 0.5f));
        for (Vec3& v : soup) v = v * scale - Vec3(7.0f * scale, 0.0f, -1e-3f * scale);
        const Scene scene = test::make_scene(soup);
        const auto bvh2 = test::build_kind(scene, "bvh2");
        for (const std::string kind : {"cwbvh6", "cwbvh8", "cwbvh8_octant"}) {
            const auto cw = test::build_kind(scene, kind);
            Rng rng(3);
            int hits = 0;
            for (int i = 0; i < 3000; ++i) {
                const Region& t = test::triangles_of(*cw);
                const Ray r = test::random_ray(rng, scene.bounds, t.records<HwTriangle>(), t.count);
                const Hit a = cw->trace(r, TraversalMode::closest_hit), b = bvh2->trace(r, TraversalMode::closest_hit);
                ASSERT_TRUE(test::same_hit(a, b)) << kind << " scale " << scale << " ray " << i;
                hits += a.valid();
            }
            EXPECT_GT(hits, 300) << kind << " scale " << scale;
        }
    }
}

TEST(Cwbvh, FusedLoopDecodesFramesNearTheFloatRangeLikeTheStepper) {
    // Nodes whose frame step is 2^121 or more (exponent byte >= 248): there 255 * scale can
    // overflow, so the fused loop decodes them without a fused multiply-add. A scene spanning
    // +-1.8e38 has such nodes near the root, and small clusters give the ordinary frames below.
    std::vector<Vec3> soup = {Vec3(-1.8e38f, -1.0f, 0.0f), Vec3(1.8e38f, -1.0f, 0.0f), Vec3(0.0f, 1.7e38f, 1.0f)};
    for (const Vec3& v : test::icosphere(1)) soup.push_back(v + Vec3(2.0f, 0.0f, 5.0f));
    for (const Vec3& v : test::tessellated_cube(2)) soup.push_back(v * 1e30f + Vec3(1e31f, 0.0f, 0.0f));
    const Scene scene = test::make_scene(soup);
    const auto cw = test::build_kind(scene, "cwbvh8");
    const Region& nodes = cw->image().region("nodes");
    uint32_t largest = 0;
    for (uint64_t i = 0; i < nodes.count; ++i)
        for (uint8_t e : nodes.records<CwNode8>()[i].e) largest = std::max<uint32_t>(largest, e);
    ASSERT_GE(largest, 248u);
    // Rays from around the small clusters (random_ray over the whole scene's box would overflow).
    Rng rng(11);
    std::unique_ptr<Stepper> stepper = cw->make_stepper();
    uint64_t steps = 0, hits = 0;
    for (int i = 0; i < 3000; ++i) {
        const Region& t = test::triangles_of(*cw);
        const Aabb around = i % 2 ? Aabb{Vec3(-10.0f), Vec3(10.0f)} : Aabb{Vec3(-3e31f), Vec3(3e31f)};
        const Ray r = test::random_ray(rng, around, t.records<HwTriangle>(), t.count);
        for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
            WorkCounts fused_work, step_work, sse_work;
            const Hit fused = cw->trace(r, mode, &fused_work);
            const Hit stepped = trace_with_stepper(*stepper, r, mode, &step_work);
            ASSERT_TRUE(test::same_hit(fused, stepped) && fused_work == step_work) << "ray " << i;
            bool ran = false;
            const Hit sse = test::trace_sse2(*cw, r, mode, &sse_work, &ran);
            ASSERT_TRUE(ran && test::same_hit(sse, stepped) && sse_work == step_work) << "SSE2 ray " << i;
            steps += step_work.steps;
            hits += stepped.valid();
        }
    }
    EXPECT_GT(steps, 3000u * 4);
    EXPECT_GT(hits, 200u);
}

template <class Node>
std::string corrupt(const AccelImage& good, const std::function<void(Node&)>& edit, uint32_t index = 0) {
    AccelImage bad = good;
    edit(bad.region("nodes").records<Node>()[index]);
    return test::error_of([&] { load_accel(std::move(bad), "bad.rtt"); });
}

TEST(Cwbvh, CorruptImagesAreRefusedByName) {
    const Scene scene = test::random_soup(5, 600);
    AccelOptions o;
    o.kind = "cwbvh8";
    const AccelImage good8 = build_accel(scene, o);
    EXPECT_NO_THROW(load_accel(AccelImage(good8), "good"));
    auto expect = [](const std::string& msg, const std::string& part) {
        EXPECT_NE(msg.find(part), std::string::npos) << "message: " << msg << "\nexpected: " << part;
    };
    expect(corrupt<CwNode8>(good8, [](CwNode8& n) { n.e[1] = 0; }), "bad.rtt: cwbvh8: node 0 has exponent byte 0");
    expect(corrupt<CwNode8>(good8, [](CwNode8& n) { n.imask ^= 1; }), "node 0 imask disagrees");
    expect(corrupt<CwNode8>(good8, [](CwNode8& n) { n.meta[0] = 0x40; }), "node 0 slot 0 has meta byte 64");
    expect(corrupt<CwNode8>(good8, [](CwNode8& n) { n.base_node = 1u << 30; }), "(out of range)");
    expect(corrupt<CwNode8>(good8, [](CwNode8& n) { n.base_node = 0; }), "(not after its parent)");
    const uint32_t tris = uint32_t(good8.region("triangles").count);
    expect(corrupt<CwNode8>(good8, [&](CwNode8& n) { n.base_tri = tris; },
                            uint32_t(good8.region("nodes").count - 1)),
           "references triangles");
    AccelImage bad_order = good8;
    bad_order.params["order"] = "random";
    expect(test::error_of([&] { load_accel(std::move(bad_order), "p.rtt"); }), "p.rtt: cwbvh8: params.order");

    o.kind = "cwbvh6";
    const AccelImage good6 = build_accel(scene, o);
    EXPECT_NO_THROW(load_accel(AccelImage(good6), "good"));
    expect(corrupt<CwNode6>(good6, [](CwNode6& n) { n.set_bases(n.base_node(), 1u << 27); },
                            uint32_t(good6.region("nodes").count - 1)),
           "bad.rtt: cwbvh6: node " + std::to_string(good6.region("nodes").count - 1));
    expect(corrupt<CwNode6>(good6, [](CwNode6& n) { n.meta[5] = meta_interior(4); }), "slot 5 has meta byte");

    o.kind = "bvh4";
    const AccelImage good4 = build_accel(scene, o);
    expect(corrupt<WideNode<4>>(good4, [](WideNode<4>& n) { n.child_ref[0] = 0, n.child_count[0] = 0; }),
           "bad.rtt: bvh4: node 0 slot 0 points to node 0 (not after its parent)");
    expect(corrupt<WideNode<4>>(good4, [](WideNode<4>& n) { n.child_ref[0] = 0, n.child_count[0] = 3, n.child_ref[1] = 0,
                                                            n.child_count[1] = 3; }),
           "is in two leaves");
    AccelImage wrong_size = good4;
    wrong_size.region("nodes").record_bytes = 64;
    expect(test::error_of([&] { load_accel(std::move(wrong_size), "w.rtt"); }), "w.rtt: bvh4 regions must hold 128-byte nodes");
}

// The compressed images' SAH cost is computed from the boxes the node step tests (dequantised
// outward): above the fp32 twin's, which uses the exact boxes of the same tree, and the exact
// figure is kept beside it.
TEST(Cwbvh, SahCostCountsTheQuantisedBoxes) {
    const Scene scene = test::random_soup(4, 3000);
    for (const auto& [fp32, compressed] : {std::pair{"bvh8", "cwbvh8"}, std::pair{"bvh6", "cwbvh6"}}) {
        const auto a = test::build_kind(scene, fp32), b = test::build_kind(scene, compressed);
        const double exact = a->image().stats["sah_cost"], quantised = b->image().stats["sah_cost"];
        EXPECT_DOUBLE_EQ(double(b->image().stats["sah_cost_exact_boxes"]), exact) << compressed;
        EXPECT_GT(quantised, exact * 1.001) << compressed;
        EXPECT_LT(quantised, exact * 2.0) << compressed;
    }
}

}  // namespace
}  // namespace rtsim
