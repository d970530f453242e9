// Sampling an animated trace (sim/sampling/sampling.h): every cluster lies in one frame, in its own
// stratum, with the frame recorded; a cluster no frame of its stratum can hold is an error naming
// the sampling fields; the strata still cover the trace, and the estimate of each frame's rays sums
// to the whole.
#include <gtest/gtest.h>

#include "sim/config/config.h"
#include "sim/sampling/sampling.h"
#include "traces/common/error.h"

namespace rtsim {
namespace {

SimConfig sampled(double fraction, uint32_t clusters) {
    SimConfig c;
    c.sampling.fraction = fraction;
    c.sampling.clusters = clusters;
    return c;
}

TEST(SamplingFrames, EveryClusterLiesInOneFrameOfItsStratum) {
    // Frames of uneven sizes whose boundaries cut strata.
    const std::vector<FrameRecord> frames = {{0, 30000}, {30000, 12000}, {42000, 45000}, {87000, 33000}};
    const uint64_t n = 120000;
    const SamplePlan plain = plan_sample(sampled(0.2, 10), n);
    const SamplePlan plan = plan_sample(sampled(0.2, 10), n, frames);
    ASSERT_EQ(plan.clusters.size(), plain.clusters.size());
    EXPECT_EQ(plan.simulated_rays, plain.simulated_rays);
    ASSERT_EQ(plan.frame_first.size(), frames.size());
    uint64_t covered = 0;
    for (size_t k = 0; k < plan.clusters.size(); ++k) {
        const SamplePlan::Cluster& c = plan.clusters[k];
        const FrameRecord& f = frames.at(c.frame);
        EXPECT_GE(c.first, f.first_ray) << k;
        EXPECT_LE(c.end(), f.first_ray + f.rays) << k;
        EXPECT_GE(c.first, c.stratum_first) << k;
        EXPECT_LE(c.end(), c.stratum_first + c.stratum_rays) << k;
        if (k) EXPECT_GE(c.first, plan.clusters[k - 1].end()) << k;  // still in trace order
        covered += c.stratum_rays;
    }
    EXPECT_EQ(covered, n);
}

TEST(SamplingFrames, AClusterNoFrameCanHoldIsAnErrorNamingTheFields) {
    // Frames of 100 rays cannot hold clusters of thousands.
    std::vector<FrameRecord> frames;
    for (uint64_t f = 0; f < 1000; ++f) frames.push_back({f * 100, 100});
    try {
        plan_sample(sampled(0.2, 5), 100000, frames);
        FAIL() << "no error";
    } catch (const Error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("fits in no frame"), std::string::npos) << what;
        EXPECT_NE(what.find("sampling.warmup_rays"), std::string::npos) << what;
    }
}

}  // namespace
}  // namespace rtsim
