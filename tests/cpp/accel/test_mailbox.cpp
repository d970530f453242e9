// Mailboxes (traces/accel/mailbox.h): with a mailbox of any size the grid, the kd-tree and the
// octree give every ray the same hit bit for bit, every work count but the triangle tests is
// unchanged, triangle tests + mailbox hits equal the tests without a mailbox, the fused loop still
// equals the stepper and its plans, and on scenes with triangles listed in several cells the
// mailbox measurably cuts triangle tests. Structures without reference lists ignore it.
#include <gtest/gtest.h>

#include "space_partition_util.h"
#include "traces/accel/mailbox.h"

namespace rtsim {
namespace {

using test::build_named;

/// The tests saved over the rays (both modes), after checking each ray against no mailbox.
uint64_t check_mailbox(const Accel& accel, uint32_t entries, const std::vector<Ray>& rays, const std::string& what) {
    StepOptions with;
    with.mailbox_entries = entries;
    uint64_t saved = 0, lookups = 0;
    int diffs = 0;
    for (const Ray& r : rays)
        for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
            WorkCounts a, b;
            const Hit ha = accel.trace(r, mode, &a, with), hb = accel.trace(r, mode, &b);
            const bool same = test::same_hit(ha, hb, TraversalMode::closest_hit);  // bits, in both modes
            const bool ledger = a.without_mailbox() == b && a.mailbox_hits <= a.mailbox_lookups;
            if ((!same || !ledger) && ++diffs <= 3)
                ADD_FAILURE() << what << ": mode " << int(mode) << " hit " << ha.prim << "/" << hb.prim << ", tests "
                              << a.tri_tests << " + " << a.mailbox_hits << " vs " << b.tri_tests;
            saved += a.mailbox_hits;
            lookups += a.mailbox_lookups;
        }
    EXPECT_EQ(diffs, 0) << what;
    EXPECT_GE(lookups, saved);
    return saved;
}

// One instance per structure, so that ctest runs them side by side (together they are the
// longest C++ test).
class MailboxPerStructure : public ::testing::TestWithParam<const char*> {};

TEST_P(MailboxPerStructure, ChangesNoHitAndKeepsTheLedgerExact) {
    const std::string name = GetParam();
    // Box-cut references (no clipping) and a fine grid list big triangles in many cells.
    const nlohmann::json settings = name == "grid"     ? nlohmann::json{{"density", 16}}
                                    : name == "kdtree" ? nlohmann::json{{"clip", false}}
                                                       : nlohmann::json{{"max_leaf_size", 2}};
    const Scene soup = test::random_soup(11, 1500);
    for (const char* scene_name : {"soup", "rotated_walls", "cornell"}) {
        const Scene& scene = std::string(scene_name) == "soup" ? soup : test::procedural(scene_name);
        const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), 12, 1500);
        // One build of the structure (the octree's clipping build dominates the test's time); the
        // mailbox is a traversal option, handed to its steppers by value.
        const auto accel = build_named(scene, name, settings);
        uint64_t last = 0;
        for (uint32_t entries : {1u, 4u, 16u, 64u}) {
            const std::string what = std::string(scene_name) + " " + name + " mailbox " + std::to_string(entries);
            const uint64_t saved = check_mailbox(*accel, entries, rays, what);
            // The fused loop, the stepper and its plans still agree, and hits match brute force.
            StepOptions step;
            step.mailbox_entries = entries;
            test::expect_structure_correct(*accel, scene, std::vector<Ray>(rays.begin(), rays.begin() + 300), what, step);
            last = saved;  // (a FIFO table is not monotone in its size: Belady's anomaly)
        }
        EXPECT_GT(last, 0u) << scene_name << " " << name << ": the mailbox saved no test";
    }
}

INSTANTIATE_TEST_SUITE_P(Mailbox, MailboxPerStructure, ::testing::Values("grid", "kdtree", "octree"),
                         [](const ::testing::TestParamInfo<const char*>& info) { return std::string(info.param); });

TEST(Mailbox, IgnoredByStructuresWithoutReferenceLists) {
    const Scene scene = test::random_soup(13, 600);
    const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), 14, 500);
    for (const std::string name : {"bvh2", "bvh2:sbvh", "bih", "bvh8", "cwbvh8"}) {
        EXPECT_EQ(check_mailbox(*build_named(scene, name), 8, rays, name), 0u) << name;
    }
}

TEST(Mailbox, TableIsFirstInFirstOut) {
    Mailbox m;
    EXPECT_FALSE(m.enabled());
    m.set_entries(3);
    for (uint32_t p : {1u, 2u, 3u}) m.insert(p);
    EXPECT_TRUE(m.contains(1) && m.contains(2) && m.contains(3));
    m.insert(4);  // replaces the oldest
    EXPECT_FALSE(m.contains(1));
    EXPECT_TRUE(m.contains(4));
    m.clear();
    EXPECT_FALSE(m.contains(4));
    m.set_entries(1000);
    EXPECT_EQ(m.entries(), Mailbox::kMaxEntries);
}

}  // namespace
}  // namespace rtsim
