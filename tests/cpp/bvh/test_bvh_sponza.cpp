// Build-time benchmark on Sponza (262,267 triangles); disabled by default, run with
//   test_bvh --gtest_also_run_disabled_tests --gtest_filter='*Sponza*'
// Target: median of 5 builds under 150 ms on one core (docs/bvh_layout.md lists measurements).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <vector>

#include <gtest/gtest.h>

#include "traces/bvh/builder.h"
#include "traces/scene/gltf_loader.h"

namespace rtsim {
namespace {

TEST(BvhBenchmark, DISABLED_SponzaBuildTime) {
    std::string path = std::string(RTSIM_SCENES_DIR) + "/sponza/Sponza.gltf";
    if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not found";
    Scene scene = load_gltf(path);
    std::vector<double> ms;
    HwBvh bvh;
    for (int i = 0; i < 5; ++i) {
        bvh = build_bvh(scene);
        ms.push_back(bvh.stats.build_ms);
    }
    std::sort(ms.begin(), ms.end());
    const BvhStats& s = bvh.stats;
    std::printf("Sponza: %zu triangles, build %.1f ms (median of 5; min %.1f, max %.1f)\n",
                scene.triangle_count(), ms[2], ms[0], ms[4]);
    std::printf("  %u nodes, %u leaves, depth %u, leaf size avg %.2f max %u, SAH cost %.3f\n",
                s.nodes, s.leaves, s.max_depth, s.avg_leaf_size, s.max_leaf_size, s.sah_cost);
    EXPECT_NO_THROW(check_bvh_invariants(bvh, scene));
    EXPECT_LT(ms[2], 150.0);
}

}  // namespace
}  // namespace rtsim
