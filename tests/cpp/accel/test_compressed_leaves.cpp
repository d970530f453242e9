// Compressed leaves (traces/accel/leaf_blocks.h) through every structure and procedural scene: the
// blocks decode to the plain triangle records byte for byte, the image of a structure whose
// leaves are runs of triangles is smaller, hits and
// every work count equal the plain image's (closest and any hit, fused loops and steppers), the
// triangle fetches address the compressed region and never exceed the plain fetch, and a
// malformed block is refused by name.
#include <gtest/gtest.h>

#include <cstring>

#include "accel_test_util.h"
#include "structure_test_util.h"
#include "tests/cpp/error_of.h"
#include "traces/accel/leaf_blocks.h"
#include "traces/scene/procedural.h"

namespace rtsim {
namespace {

std::vector<std::string> every_kind() {
    std::vector<std::string> kinds;
    for (const AccelKindInfo& k : accel_kinds()) kinds.push_back(k.name);
    return kinds;
}

/// The triangle fetch bytes of one ray's plans, summed, and whether each lay in `region`.
uint64_t triangle_fetch_bytes(Stepper& s, const Ray& ray, TraversalMode mode, const Region& region, bool* inside,
                              uint64_t* fetches = nullptr) {
    uint64_t bytes = 0;
    s.begin(ray, mode);
    while (!s.done()) {
        const StepPlan& p = s.plan();
        for (int i = 0; i < p.fetch_count; ++i) {
            if (p.fetch[i].kind != DataKind::triangle) continue;
            bytes += p.fetch[i].bytes;
            if (fetches) ++*fetches;
            *inside = *inside && p.fetch[i].addr >= region.base &&
                      p.fetch[i].addr + p.fetch[i].bytes <= region.base + region.size_bytes();
        }
        s.execute();
    }
    return bytes;
}

TEST(CompressedLeaves, EveryKindAndSceneDecodesExactlyAndTracesTheSame) {
    for (const std::string& name : procedural_scene_names()) {
        const Scene& scene = test::procedural(name);
        const std::vector<HwTriangle> tris = test::hw_triangles(scene);
        const std::vector<Ray> rays = test::random_rays(scene, tris, 5, 300);
        for (const std::string& kind : every_kind()) {
            const auto plain = test::build_kind(scene, kind);
            const auto packed = test::build_kind(scene, kind + test::kCompressedLeaves);
            const std::string what = name + " " + kind;
            ASSERT_TRUE(packed->image().has_region(kLeafBlocksRegion)) << what;
            EXPECT_FALSE(packed->image().has_region("triangles")) << what;
            // Lossless: the decoded triangles are the plain records, byte for byte.
            const Region& plain_tris = plain->image().region("triangles");
            const TriangleStore store = TriangleStore::open(packed->image(), what);
            ASSERT_EQ(store.count(), plain_tris.count) << what;
            EXPECT_EQ(std::memcmp(store.triangles(), plain_tris.bytes.data(), plain_tris.size_bytes()), 0) << what;
            // Leaves that are runs of triangles share their vertices; a structure that fetches
            // single triangles keeps one-line blocks, mostly of one triangle (52 bytes with its
            // flags, 56 with an instance id too).
            if (plain->capabilities().mailbox)
                EXPECT_LE(packed->image().region(kLeafBlocksRegion).size_bytes(), 56 * store.count()) << what;
            else
                EXPECT_LT(packed->image().footprint_bytes(), plain->image().footprint_bytes()) << what;
            // Hits and work: fused loop and stepper against the plain image, both modes.
            const Region& blocks = packed->image().region(kLeafBlocksRegion);
            auto a = packed->make_stepper(), b = plain->make_stepper();
            bool inside = true;
            for (const Ray& r : rays)
                for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
                    WorkCounts wp, wq, ws;
                    const Hit hp = plain->trace(r, mode, &wp), hq = packed->trace(r, mode, &wq);
                    const Hit hs = trace_with_stepper(*a, r, mode, &ws);
                    ASSERT_TRUE(test::same_hit(hp, hq, mode) && test::same_hit(hp, hs, mode)) << what;
                    ASSERT_TRUE(wp == wq && wp == ws) << what;
                    const uint64_t packed_bytes = triangle_fetch_bytes(*a, r, mode, blocks, &inside);
                    bool plain_inside = true;
                    uint64_t leaf_fetches = 0;
                    const uint64_t plain_bytes = triangle_fetch_bytes(*b, r, mode, plain_tris, &plain_inside, &leaf_fetches);
                    // A single-triangle fetch brings its whole block (at most a 64-byte line);
                    // a leaf's blocks are at most its records plus a block header and shared
                    // words (a lone triangle with its flags: 52 bytes).
                    const uint64_t bound = plain->capabilities().mailbox ? wp.tri_tests * kSingleFetchBlockBytes
                                                                 : plain_bytes + 8 * leaf_fetches;
                    EXPECT_LE(packed_bytes, bound) << what;
                }
            EXPECT_TRUE(inside) << what << ": a triangle fetch outside the compressed region";
        }
    }
}

TEST(CompressedLeaves, SavesBytesOnMeshesAndSaysSo) {
    const Scene& scene = test::procedural("cornell");
    const auto packed = test::build_kind(scene, "cwbvh8" + test::kCompressedLeaves);
    const nlohmann::json& s = packed->image().stats.at("leaf_blocks");
    EXPECT_EQ(s.at("layout"), "compressed");
    EXPECT_EQ(s.at("triangles").get<uint64_t>(), scene.triangles.size());
    EXPECT_LT(s.at("ratio").get<double>(), 0.8);  // shared vertices: well under the 48-byte record
    EXPECT_EQ(s.at("bytes").get<uint64_t>(), packed->image().region(kLeafBlocksRegion).size_bytes());
}

TEST(CompressedLeaves, BadSettingsAndBlocksAreNamed) {
    const Scene& scene = test::procedural("cornell");
    AccelOptions o;
    o.kind = "bvh2";
    o.settings["leaf_block_bytes"] = 16;
    EXPECT_NE(test::error_of([&] { build_accel(scene, o); }).find("leaf_block_bytes"), std::string::npos);
    o.settings = {{"compressed_leaves", true}};
    AccelImage image = build_accel(scene, o);
    Region& r = image.region(kLeafBlocksRegion);
    const uint8_t tris = r.records<uint8_t>()[0];
    r.records<uint8_t>()[0] = 0;  // a block of no triangles
    const std::string err = test::error_of([&] { load_accel(image, "bad.rtt"); });
    EXPECT_NE(err.find("bad.rtt"), std::string::npos) << err;
    EXPECT_NE(err.find("leaf_blocks' block at byte 0"), std::string::npos) << err;
    r.records<uint8_t>()[0] = tris;
    r.records<uint8_t>()[3] = 1;  // a size that does not match the contents
    EXPECT_NE(test::error_of([&] { load_accel(image, "bad.rtt"); }).find("does not match"), std::string::npos);
}

}  // namespace
}  // namespace rtsim
