// Ray-box / ray-triangle pipelines: one issue per initiation interval, width tests per issue,
// and a shared pool of k pipelines sustaining k issues per initiation interval.
#include <gtest/gtest.h>

#include <map>

#include "rtl_model/isect/pipeline.h"
#include "rtl_model/traversal/step_demand.h"
#include "model_test_util.h"

namespace rtsim {
namespace {

using test::TestKernel;

/// `tests` tests issued as the step-demand function counts them at the pipeline's width.
Cycle issue(Pipeline& p, Cycle time, uint32_t tests, uint32_t width = 1) {
    return p.issue(time, issues_for(tests, width), tests);
}

PipelineConfig config(uint32_t latency, uint32_t ii, uint32_t width, uint32_t shared_count = 4) {
    PipelineConfig c;
    c.latency = latency;
    c.initiation_interval = ii;
    c.width = width;
    c.sharing = Sharing::per_unit;
    c.shared_count = shared_count;
    return c;
}

TEST(Pipeline, SustainsOneIssuePerInitiationInterval) {
    TestKernel kernel;
    const Cycle latency = 8, ii = 3;
    Pipeline p("box", config(uint32_t(latency), uint32_t(ii), 1), false);
    // N back-to-back issues (all ready at cycle 10): issue i finishes at 10 + i * II + latency.
    const uint32_t n = 50;
    for (uint32_t i = 0; i < n; ++i) EXPECT_EQ(issue(p, 10, 1), 10 + i * ii + latency) << "issue " << i;
    // One request of N tests: the last result at first + (N-1) * II + latency.
    Pipeline q("tri", config(uint32_t(latency), uint32_t(ii), 1), false);
    EXPECT_EQ(issue(q, 10, n), 10 + (n - 1) * ii + latency);
    EXPECT_EQ(q.issues(), n);
    EXPECT_EQ(q.tests(), n);
    // An idle pipeline starts at once.
    EXPECT_EQ(issue(q, 10000, 1), 10000 + latency);
}

TEST(Pipeline, WidthTestsPerIssue) {
    TestKernel kernel;
    Pipeline p("box", config(8, 2, 2), false);
    EXPECT_EQ(issue(p, 0, 2, 2), 8u);            // one issue: both boxes of a node
    EXPECT_EQ(issue(p, 0, 5, 2), 2u + 2 * 2 + 8);  // 3 issues after the first: 2, 4, 6
    EXPECT_EQ(p.issues(), 4u);
    EXPECT_EQ(p.tests(), 7u);
    EXPECT_EQ(issue(p, 100, 0, 2), 100u);  // nothing to test: no time
    EXPECT_EQ(p.issues(), 4u);
}

TEST(Pipeline, SharedPoolGivesKIssuesPerInterval) {
    TestKernel kernel;
    const uint32_t k = 4, ii = 2, latency = 10;
    Pipeline pool("pool", config(latency, ii, 1, k), true);
    EXPECT_EQ(pool.pipelines(), k);
    // 100 single issues from many units, all at cycle 0: k start in every interval.
    std::map<Cycle, int> per_interval;
    Cycle last = 0;
    for (int i = 0; i < 100; ++i) {
        Cycle done = issue(pool, 0, 1);
        ++per_interval[(done - latency) / ii];
        last = std::max(last, done);
    }
    ASSERT_EQ(per_interval.size(), 25u);
    for (const auto& [interval, n] : per_interval) EXPECT_EQ(n, int(k)) << "interval " << interval;
    EXPECT_LT(last, 25u * ii + latency);
    // Utilization over exactly those 25 intervals is 1.
    EXPECT_NEAR(pool.stats_json(25 * ii)["utilization"].get<double>(), 1.0, 1e-9);
    // A private pipeline with the same config takes k times longer for the same work.
    Pipeline one("one", config(latency, ii, 1, k), false);
    for (int i = 0; i < 100; ++i) last = issue(one, 0, 1);
    EXPECT_EQ(last, 99u * ii + latency);
}

}  // namespace
}  // namespace rtsim
