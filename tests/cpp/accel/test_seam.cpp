// The acceleration-structure seam itself: image layout and descriptor round trip through a trace
// file, the registry's errors, locality trees, and structural validation refusing images whose
// checksums are fine but whose content is not.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tests/cpp/error_of.h"
#include "../bvh/bvh_test_scenes.h"
#include "traces/accel/accel_io.h"
#include "traces/accel/bvh2/bvh2.h"
#include "traces/common/error.h"
#include "tests/cpp/process_temp_dir.h"

using namespace rtsim;

namespace {

using rtsim::test::error_of;

AccelImage small_bvh2(size_t triangles = 500, uint64_t seed = 3) {
    AccelOptions o;
    return build_accel(test::make_scene(test::random_triangles(triangles, seed)), o);
}

std::string temp_file(const std::string& name) {
    return (test::process_temp_dir("seam") / name).string();
}

}  // namespace

TEST(AccelImage, RegionsArePlacedOnGranules) {
    AccelImage image;
    image.add_region("a", DataKind::node, 64, 10);
    Region big;  // more than one granule (not allocated: placement needs only the counts)
    big.name = "b";
    big.record_bytes = 48;
    big.count = (5ull << 30) / 48;
    image.regions.push_back(std::move(big));
    image.add_region("c", DataKind::prim_ref, 4, 0);
    image.place_regions();
    EXPECT_EQ(image.regions[0].base, 1ull << 32);
    EXPECT_EQ(image.regions[1].base, 2ull << 32);
    EXPECT_EQ(image.regions[2].base, 4ull << 32);  // b spans two granules
    EXPECT_EQ(image.end_address(), 5ull << 32);
    EXPECT_EQ(image.regions[1].address(2), (2ull << 32) + 96);
    EXPECT_NE(error_of([&] { image.add_region("a", DataKind::node, 64, 1); }).find("'a' added twice"), std::string::npos);
    EXPECT_NE(error_of([&] { (void)image.region("zzz"); }).find("no region 'zzz'"), std::string::npos);
}

TEST(AccelImage, RegionReferencesSurviveLaterRegions) {
    // A builder may hold the first region's records while it adds the next ones.
    AccelImage image;
    Region& first = image.add_region("first", DataKind::node, 64, 4);
    const uint8_t* bytes = first.bytes.data();
    for (int i = 0; i < 64; ++i) image.add_region("r" + std::to_string(i), DataKind::triangle, 48, 1);
    EXPECT_EQ(&first, &image.region("first"));
    EXPECT_EQ(first.bytes.data(), bytes);
    EXPECT_EQ(first.count, 4u);
}

TEST(AccelImage, ImageRoundTripsThroughATrace) {
    const AccelImage built = small_bvh2();
    const std::string path = temp_file("roundtrip.rtt");
    {
        TraceWriter w(path);
        write_accel_image(w, built);
        w.close();
    }
    TraceReader r(path);
    const AccelImage read = read_accel_image(r);
    EXPECT_EQ(read.kind, "bvh2");
    EXPECT_EQ(read.descriptor(), built.descriptor());
    ASSERT_EQ(read.regions.size(), built.regions.size());
    for (size_t i = 0; i < read.regions.size(); ++i) {
        ASSERT_EQ(read.regions[i].bytes.size(), built.regions[i].bytes.size());
        EXPECT_EQ(std::memcmp(read.regions[i].bytes.data(), built.regions[i].bytes.data(), read.regions[i].bytes.size()), 0);
    }
    // Deterministic: the same scene builds the same bytes (no wall time in the descriptor).
    EXPECT_EQ(small_bvh2().descriptor().dump(), built.descriptor().dump());
    std::filesystem::remove(path);
}

TEST(AccelImage, MalformedDescriptorsNameTheField) {
    nlohmann::json d = small_bvh2().descriptor();
    auto refused = [&](nlohmann::json bad) { return error_of([&] { AccelImage::from_descriptor(bad, "t.rtt"); }); };
    nlohmann::json no_kind = d;
    no_kind.erase("kind");
    EXPECT_NE(refused(no_kind).find("'kind'"), std::string::npos);
    nlohmann::json bad_kind = d;
    bad_kind["regions"][0]["kind"] = "bananas";
    EXPECT_NE(refused(bad_kind).find("regions[0].kind"), std::string::npos);
    nlohmann::json moved = d;
    moved["regions"][1]["base"] = 12345u;
    EXPECT_NE(refused(moved).find("'triangles' is not at its address"), std::string::npos);
    nlohmann::json negative = d;
    negative["regions"][0]["count"] = -1;
    EXPECT_NE(refused(negative).find("regions[0].count"), std::string::npos);
    nlohmann::json huge = d;
    huge["regions"][0]["count"] = 1ull << 50;
    EXPECT_NE(refused(huge).find("larger than 2^40"), std::string::npos);
    EXPECT_NE(refused(nlohmann::json::array()).find("t.rtt"), std::string::npos);
}

TEST(Registry, UnknownKindsAndBuildersAreListed) {
    AccelOptions o;
    o.kind = "octree9";
    std::string msg = error_of([&] { validate_accel_options(o); });
    EXPECT_NE(msg.find("'octree9'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("bvh2"), std::string::npos) << msg;
    o.kind = "bvh2";
    o.builder = "magic";
    msg = error_of([&] { validate_accel_options(o); });
    EXPECT_NE(msg.find("no builder 'magic'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("binned"), std::string::npos) << msg;
    AccelImage image = small_bvh2();
    image.kind = "unheard_of";
    msg = error_of([&] { load_accel(std::move(image), "x.rtt"); });
    EXPECT_NE(msg.find("x.rtt: unknown acceleration structure 'unheard_of'"), std::string::npos) << msg;
    EXPECT_FALSE(accel_kinds().empty());
}

TEST(Bvh2Validation, CorruptImagesAreRefusedByName) {
    const AccelImage good = small_bvh2(200);
    EXPECT_NO_THROW(load_accel(AccelImage(good), "good"));
    auto with_node = [&](uint32_t index, const std::function<void(HwNode&)>& edit) {
        AccelImage bad = good;
        edit(bad.region("nodes").records<HwNode>()[index]);
        return error_of([&] { load_accel(std::move(bad), "bad.rtt"); });
    };
    // A child index out of range, a node pointing to itself, a leaf past the triangles, a huge leaf.
    std::string msg = with_node(0, [](HwNode& n) { n.child_ref[0] = 1u << 30, n.child_count[0] = 0; });
    EXPECT_NE(msg.find("bad.rtt: binary BVH: node 0 child 0 points to node 1073741824 (out of range)"), std::string::npos) << msg;
    msg = with_node(0, [](HwNode& n) { n.child_ref[1] = 0, n.child_count[1] = 0; });
    EXPECT_NE(msg.find("not after its parent"), std::string::npos) << msg;
    const uint64_t tris = good.region("triangles").count;
    msg = with_node(0, [&](HwNode& n) { n.child_ref[0] = uint32_t(tris - 1), n.child_count[0] = 2; });
    EXPECT_NE(msg.find("references triangles"), std::string::npos) << msg;
    msg = with_node(0, [](HwNode& n) { n.child_ref[0] = 0, n.child_count[0] = 0xFFFFFF; });
    EXPECT_NE(msg.find("is a leaf of 16777215 triangles"), std::string::npos) << msg;
    // An empty triangle region under a tree that references triangles.
    AccelImage no_tris = good;
    no_tris.region("triangles").count = 0;
    no_tris.region("triangles").bytes.resize(0);
    msg = error_of([&] { load_accel(std::move(no_tris), "empty.rtt"); });
    EXPECT_NE(msg.find("empty.rtt: binary BVH"), std::string::npos) << msg;
}

TEST(Bvh2Locality, TreeMirrorsTheNodes) {
    const std::unique_ptr<Accel> accel = load_accel(small_bvh2(1000), "t");
    const Region& nodes = accel->image().region("nodes");
    const LocalityTree t = bvh2_locality_tree(nodes.records<HwNode>(), nodes.count);
    ASSERT_EQ(t.size(), nodes.count);
    uint64_t bytes = 0, children = 0;
    for (uint32_t i = 0; i < t.size(); ++i) {
        bytes += t.bytes[i];
        children += t.child_begin[i + 1] - t.child_begin[i];
        for (uint32_t k = t.child_begin[i]; k < t.child_begin[i + 1]; ++k) EXPECT_GT(t.children[k], i);
    }
    EXPECT_EQ(children, nodes.count - 1);  // every node but the root is someone's child
    EXPECT_EQ(bytes, accel->image().footprint_bytes());
    const LocalityPartition p = accel->partition(4096);
    EXPECT_NO_THROW(check_tree_partition(t, p));
    EXPECT_EQ(p.root_group, p.group_of[0]);
}
