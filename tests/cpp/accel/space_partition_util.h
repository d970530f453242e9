#pragma once
// Helpers for the space-partitioning structures' tests (kd-tree, BIH, octree; the grid and LBVH
// where they share a test): building any kind and builder through the registry with settings, and
// the checks every structure must pass on a set of rays.
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "structure_test_util.h"
#include "traces/accel/accel.h"

namespace rtsim::test {

/// The structures these tests sweep: KIND or KIND:BUILDER.
inline const std::vector<std::string>& partition_kinds() {
    static const std::vector<std::string> kinds = {"kdtree",      "bih",          "bih:wachter_keller", "bih:lbvh",
                                                   "octree",      "bvh2:lbvh",    "bvh2:sweep",         "bvh2:median",
                                                   "bkd",         "bkd:sweep",    "bkd:median",         "gkbvh",
                                                   "gkbvh:boxes", "bih:sweep",    "obvh2",              "obvh2:sbvh",
                                                   "bvh2:lrt"};
    return kinds;
}

inline std::unique_ptr<Accel> build_named(const Scene& scene, const std::string& name,
                                          const nlohmann::json& settings = nlohmann::json::object()) {
    AccelOptions o;
    const size_t colon = name.find(':');
    o.kind = name.substr(0, colon);
    if (colon != std::string::npos) o.builder = name.substr(colon + 1);
    o.settings = settings;
    return load_accel(build_accel(scene, o), name);
}

/// Hits identical to brute force and to the binary BVH (closest: bits; any: hit or miss), and on
/// every ray the fused loop's work equal to the stepper's and to what the stepper's plans asked
/// for. Returns the closest hits found (so callers can require the rays to exercise hits).
inline int expect_structure_correct(const Accel& accel, const Scene& scene, const std::vector<Ray>& rays,
                                    const std::string& what, const StepOptions& step = {}) {
    const std::vector<HwTriangle> tris = hw_triangles(scene);
    const Agreement brute = compare_rays(tracer(accel, step), brute_force(tris), rays, what + " vs brute force");
    EXPECT_EQ(brute.diffs, 0) << what;
    AccelOptions o;
    const std::unique_ptr<Accel> bvh = load_accel(build_accel(scene, o), "bvh2");
    EXPECT_EQ(compare_rays(tracer(accel, step), tracer(*bvh), rays, what + " vs bvh2").diffs, 0) << what;
    std::unique_ptr<Stepper> s = accel.make_stepper(step);
    int work_diffs = 0;
    for (const Ray& r : rays)
        for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
            WorkCounts fused;
            const Hit h = accel.trace(r, mode, &fused, step);
            const WorkCounts planned = tally_plans(*s, r, mode);
            WorkCounts stepped = s->work();
            stepped.mailbox_lookups = stepped.mailbox_hits = 0;  // the plans do not show the mailbox
            work_diffs += !(fused == s->work()) || !(planned == stepped) || !same_hit(h, s->hit(), mode);
        }
    EXPECT_EQ(work_diffs, 0) << what << ": trace(), the stepper and its plans disagree";
    return brute.hits;
}

}  // namespace rtsim::test
