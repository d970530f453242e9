// The space-partitioning structures at the seam: validation refusing corrupt images by name, the
// registry's builders and settings (defaults, overrides, refusals naming the setting), the
// stack entry sizes the model takes from them, and their images through a trace file.
#include <gtest/gtest.h>

#include <filesystem>

#include "space_partition_util.h"
#include "tests/cpp/error_of.h"
#include "traces/accel/accel_io.h"
#include "traces/accel/bih/bih.h"
#include "traces/accel/kdtree/kdtree.h"
#include "traces/accel/octree/octree.h"
#include "traces/common/error.h"
#include "tests/cpp/process_temp_dir.h"

namespace rtsim {
namespace {

using test::build_named;
using test::error_of;

/// The message load_accel gives for `good` edited by `edit` ("" if it is accepted).
std::string refused(const AccelImage& good, const std::function<void(AccelImage&)>& edit) {
    AccelImage bad = good;
    edit(bad);
    return error_of([&] { load_accel(std::move(bad), "bad.rtt"); });
}

template <class Node>
Node* nodes_of(AccelImage& im) {
    return im.region("nodes").records<Node>();
}

TEST(SpacePartitionValidation, KdTreeRefusesCorruptImagesByName) {
    AccelOptions o;
    o.kind = "kdtree";
    const AccelImage good = build_accel(test::random_soup(4, 400), o);
    EXPECT_EQ(refused(good, [](AccelImage&) {}), "");
    std::string msg = refused(good, [](AccelImage& im) { nodes_of<KdNode>(im)[0] = KdNode::interior(0, 0.0f, 0); });
    EXPECT_NE(msg.find("bad.rtt: kd-tree: node 0"), std::string::npos) << msg;
    msg = refused(good, [](AccelImage& im) {
        const Region& r = im.region("nodes");
        nodes_of<KdNode>(im)[r.count - 1] = KdNode::make_leaf(0, uint32_t(im.region("prim_refs").count + 1));
    });
    EXPECT_NE(msg.find("lists prim_refs"), std::string::npos) << msg;
    const uint32_t tris = uint32_t(good.region("triangles").count);
    msg = refused(good, [&](AccelImage& im) { im.region("prim_refs").records<uint32_t>()[3] = tris; });
    EXPECT_NE(msg.find("prim_refs entry 3 names triangle " + std::to_string(tris)), std::string::npos) << msg;
    msg = refused(good, [](AccelImage& im) {
        KdNode& root = nodes_of<KdNode>(im)[0];
        root = KdNode::interior(root.axis(), 1e30f, root.above());
    });
    EXPECT_NE(msg.find("outside its cell"), std::string::npos) << msg;
    msg = refused(good, [](AccelImage& im) { im.params.erase("bounds"); });
    EXPECT_NE(msg.find("bad.rtt: kdtree params: 'bounds' is missing"), std::string::npos) << msg;
    msg = refused(good, [](AccelImage& im) { im.region("nodes").record_bytes = 16; });
    EXPECT_NE(msg.find("8-byte nodes"), std::string::npos) << msg;
}

TEST(SpacePartitionValidation, BihAndOctreeRefuseCorruptImagesByName) {
    AccelOptions o;
    o.kind = "bih";
    const AccelImage bih = build_accel(test::random_soup(5, 400), o);
    EXPECT_EQ(refused(bih, [](AccelImage&) {}), "");
    std::string msg = refused(bih, [](AccelImage& im) { nodes_of<BihNode>(im)[0] = BihNode::interior(1, 0, 0.0f, 0.0f); });
    EXPECT_NE(msg.find("bad.rtt: BIH: node 0 names child 0"), std::string::npos) << msg;
    msg = refused(bih, [](AccelImage& im) {
        BihNode& root = nodes_of<BihNode>(im)[0];
        root = BihNode::interior(root.axis(), root.left(), std::nanf(""), root.clip(1));
    });
    EXPECT_NE(msg.find("NaN clip plane"), std::string::npos) << msg;
    msg = refused(bih, [](AccelImage& im) {
        const uint64_t n = im.region("nodes").count;
        for (uint64_t i = 0; i < n; ++i)
            if (nodes_of<BihNode>(im)[i].leaf()) {
                nodes_of<BihNode>(im)[i] = BihNode::make_leaf(0, 1);  // the first triangle twice, others lost
            }
    });
    EXPECT_NE(msg.find("is in two leaves"), std::string::npos) << msg;

    o.kind = "octree";
    const AccelImage oct = build_accel(test::random_soup(6, 400), o);
    EXPECT_EQ(refused(oct, [](AccelImage&) {}), "");
    msg = refused(oct, [](AccelImage& im) {
        OctNode& root = nodes_of<OctNode>(im)[0];
        const float centre[3] = {1e30f, root.centre(1), root.centre(2)};
        root = OctNode::interior(root.mask(), root.first_child(), centre);
    });
    EXPECT_NE(msg.find("bad.rtt: octree: node 0's centre is outside its cell on axis 0"), std::string::npos) << msg;
    msg = refused(oct, [](AccelImage& im) {
        OctNode& root = nodes_of<OctNode>(im)[0];
        const float centre[3] = {root.centre(0), root.centre(1), root.centre(2)};
        root = OctNode::interior(root.mask(), uint32_t(im.region("nodes").count), centre);
    });
    EXPECT_NE(msg.find("out of range"), std::string::npos) << msg;
    msg = refused(oct, [](AccelImage& im) { im.region("nodes").record_bytes = 8; });
    EXPECT_NE(msg.find("bad.rtt: octree regions must hold 16-byte nodes"), std::string::npos) << msg;
    msg = refused(oct, [](AccelImage& im) { im.region("prim_refs").kind = DataKind::triangle; });
    EXPECT_NE(msg.find("octree regions must be of data kinds node, prim_ref and triangle"), std::string::npos) << msg;
}

TEST(SpacePartitionSeam, StackEntriesOpKindsAndManifestKeys) {
    const Scene scene = test::random_soup(7, 500);
    struct Want {
        std::string name;
        uint32_t entry_bytes, width, node_bytes;
        bool mailbox;
    };
    for (const Want& w : std::vector<Want>{{"kdtree", 12, 2, 8, true},
                                           {"bih", 12, 2, 12, false},
                                           {"octree", 32, 8, 16, true},
                                           {"grid", 8, 0, 8, true},
                                           {"bvh2:lbvh", 8, 2, 64, false}}) {
        const auto a = build_named(scene, w.name);
        EXPECT_EQ(a->stack_entry_bytes(), w.entry_bytes) << w.name;
        EXPECT_EQ(a->image().stats["stack_entry_bytes"], w.entry_bytes) << w.name;
        EXPECT_EQ(a->capabilities().mailbox, w.mailbox) << w.name;
        EXPECT_EQ(a->image().stats["node_bytes"], w.node_bytes) << w.name;
        if (w.width) {
            EXPECT_EQ(a->image().stats["width"], w.width) << w.name;
        }
        const std::vector<OpKind> ops = a->op_kinds();
        const bool plane = std::find(ops.begin(), ops.end(), OpKind::plane) != ops.end();
        EXPECT_EQ(plane, w.name == "kdtree" || w.name == "bih" || w.name == "octree") << w.name;
        if (a->kind() != "grid") {
            EXPECT_GT(a->image().stats["sah_cost"].get<double>(), 0.0) << w.name;
        }
        // Every kind records its resolved settings.
        EXPECT_TRUE(a->image().stats["build_settings"].is_object()) << w.name;
        EXPECT_GE(a->max_stack_entries(), a->kind() == "grid" ? 0u : 1u) << w.name;
    }
}

TEST(SpacePartitionSeam, BuilderSettingsAreDataAndRefusedByName) {
    const Scene scene = test::random_soup(8, 600);
    // Defaults come from the documented Configs, and overrides land in the manifest's stats.
    const auto kd = build_named(scene, "kdtree", {{"empty_bonus", 0.5}, {"max_depth", 9}});
    const nlohmann::json& s = kd->image().stats;
    EXPECT_FLOAT_EQ(s["build_settings"]["empty_bonus"].get<float>(), 0.5f);
    EXPECT_EQ(s["build_settings"]["max_depth"], 9);
    EXPECT_FLOAT_EQ(s["build_settings"]["traversal_cost"].get<float>(), KdConfig{}.traversal_cost);
    EXPECT_EQ(s["build_set"], nlohmann::json({{"empty_bonus", 0.5}, {"max_depth", 9}}));
    EXPECT_LE(s["max_depth"].get<int>(), 9);
    // Settings change the tree; the same settings give the same bytes (deterministic).
    const auto bvh8 = build_named(scene, "bvh2", {{"max_leaf_size", 8}, {"bins", 8}});
    const auto bvh1 = build_named(scene, "bvh2", {{"max_leaf_size", 1}});
    EXPECT_LT(bvh8->image().stats["nodes"].get<uint64_t>(), bvh1->image().stats["nodes"].get<uint64_t>());
    EXPECT_EQ(bvh8->image().stats["config"]["bins"], 8);
    const auto again = build_named(scene, "kdtree", {{"max_depth", 9}, {"empty_bonus", "0.5"}});  // text, as a CLI gives it
    EXPECT_EQ(again->image().region("nodes").size_bytes(), kd->image().region("nodes").size_bytes());
    EXPECT_EQ(std::memcmp(again->image().region("nodes").bytes.data(), kd->image().region("nodes").bytes.data(),
                          kd->image().region("nodes").size_bytes()),
              0);
    // The grid's density and SBVH's alpha reach their builders.
    const auto coarse = build_named(scene, "grid", {{"density", 0.5}});
    const auto fine = build_named(scene, "grid", {{"density", 8}});
    EXPECT_LT(coarse->image().region("cells").count, fine->image().region("cells").count);
    const auto no_spatial = build_named(scene, "bvh2:sbvh", {{"alpha", 2.0}});
    EXPECT_EQ(no_spatial->image().stats["sbvh"]["spatial_splits"], 0);
    // Refusals name the structure, the builder and the setting.
    std::string msg = error_of([&] { build_named(scene, "kdtree", {{"bins", 8}}); });
    EXPECT_NE(msg.find("accel kdtree (builder sah): unknown setting 'bins' (it takes: traversal_cost"), std::string::npos) << msg;
    msg = error_of([&] { build_named(scene, "bvh2", {{"max_leaf_size", 0}}); });
    EXPECT_NE(msg.find("setting 'max_leaf_size' = 0 is out of range [1, 64]"), std::string::npos) << msg;
    msg = error_of([&] { build_named(scene, "octree", {{"clip", 3}}); });
    EXPECT_NE(msg.find("setting 'clip' must be true or false"), std::string::npos) << msg;
    msg = error_of([&] { build_named(scene, "bvh2:lbvh", {{"bins", 8}}); });
    EXPECT_NE(msg.find("unknown setting 'bins'"), std::string::npos) << msg;
    // The schema lists each builder's settings with defaults.
    const nlohmann::json schema = accel_settings_schema("bvh2", "sbvh");
    EXPECT_EQ(schema["alpha"]["type"], "float");
    EXPECT_EQ(schema["bins"]["default"], 16);
    EXPECT_TRUE(accel_settings_schema("octree").contains("max_depth"));
}

TEST(SpacePartitionSeam, ImagesRoundTripThroughATraceFile) {
    const Scene scene = test::random_soup(9, 500);
    const std::string path = (test::process_temp_dir("space_partition") / "space_partition.rtt").string();
    for (const char* name : {"kdtree", "bih", "octree"}) {
        const auto built = build_named(scene, name);
        {
            TraceWriter w(path);
            write_accel_image(w, built->image());
            w.close();
        }
        TraceReader r(path);
        const auto loaded = load_accel(read_accel_image(r), path);
        EXPECT_EQ(loaded->kind(), built->kind());
        const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), 3, 300);
        EXPECT_EQ(test::compare_rays(test::tracer(*loaded), test::tracer(*built), rays, name).diffs, 0) << name;
        EXPECT_EQ(read_accel_descriptor(r)["stats"]["stack_entry_bytes"], built->stack_entry_bytes()) << name;
    }
}

}  // namespace
}  // namespace rtsim
