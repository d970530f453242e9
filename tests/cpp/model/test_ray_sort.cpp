// The sorting stage at dispatch: every ray handed out exactly once under every key and policy,
// each window in key order (stable), and no ray ready before its window was sorted.
#include <gtest/gtest.h>

#include <random>
#include <set>
#include <vector>

#include "rtl_model/dispatch/dispatch.h"
#include "rtl_model/traversal/simt/coalescer.h"

using namespace rtsim;

namespace {

/// `total` random rays in trace order, ids 0 .. total - 1.
class RandomStream : public RayStream {
public:
    explicit RandomStream(uint64_t total) : m_total(total) {}
    size_t read_chunk(size_t max, std::vector<RayJob>* out) override {
        const size_t n = size_t(std::min<uint64_t>(max, m_total - m_next));
        std::uniform_real_distribution<float> u(-1.0f, 1.0f);
        for (size_t i = 0; i < n; ++i) {
            Ray ray;
            ray.origin = Vec3(u(m_rng), u(m_rng), u(m_rng)) * 10.0f;
            ray.direction = Vec3(u(m_rng), u(m_rng), u(m_rng));
            out->push_back(RayJob{m_next++, ray, false, 0});
        }
        return n;
    }
    uint64_t total_rays() const override { return m_total; }

private:
    uint64_t m_total, m_next = 0;
    std::mt19937 m_rng{7};
};

std::vector<RayJob> drain(RayDealer& dealer, uint32_t units) {
    std::vector<RayJob> jobs;
    RayJob job;
    for (uint32_t turn = 0; dealer.next_ray(turn % units, &job); ++turn) jobs.push_back(job);
    return jobs;
}

TEST(RaySort, EveryRayIsHandedOutExactlyOnce) {
    for (RaySort sort : {RaySort::none, RaySort::octant, RaySort::morton, RaySort::origin_direction})
        for (DispatchPolicy policy : {DispatchPolicy::interleaved, DispatchPolicy::on_demand}) {
            DispatchConfig config;
            config.sort = sort;
            config.policy = policy;
            config.chunk_rays = 700;  // windows cut across chunk ends
            config.sort_window = 256;
            const uint64_t total = 2000;
            RandomStream stream(total);
            RayDealer dealer(config, 3, stream);
            const std::vector<RayJob> jobs = drain(dealer, 3);
            std::set<uint64_t> ids;
            for (const RayJob& j : jobs) ids.insert(j.id);
            EXPECT_EQ(jobs.size(), total) << kRaySortChoices.name(sort);
            EXPECT_EQ(ids.size(), total) << kRaySortChoices.name(sort);
            EXPECT_EQ(*ids.rbegin(), total - 1);
            EXPECT_TRUE(dealer.exhausted());
        }
}

TEST(RaySort, WindowsComeOutInStableKeyOrderAndWaitForTheStage) {
    DispatchConfig config;
    config.sort = RaySort::octant;
    config.policy = DispatchPolicy::on_demand;  // hand-out order is the stage's order
    config.chunk_rays = 512;
    config.sort_window = 128;
    config.sort_rays_per_cycle = 2;
    config.sort_latency = 10;
    RandomStream stream(512);
    RayDealer dealer(config, 1, stream);
    const std::vector<RayJob> jobs = drain(dealer, 1);
    ASSERT_EQ(jobs.size(), 512u);
    for (size_t w = 0; w < 4; ++w) {
        const Cycle ready = (w + 1) * 128 / 2 + 10;  // sorted at 2 rays/cycle, then the latency
        for (size_t i = w * 128; i < (w + 1) * 128; ++i) {
            EXPECT_EQ(jobs[i].not_before, ready) << "ray " << i;
            if (i == w * 128) continue;
            const uint32_t a = ray_sort_key(jobs[i - 1].ray, config.sort, Vec3(0), Vec3(0));
            const uint32_t b = ray_sort_key(jobs[i].ray, config.sort, Vec3(0), Vec3(0));
            EXPECT_LE(a, b) << "ray " << i;
            if (a == b) {
                EXPECT_LT(jobs[i - 1].id, jobs[i].id) << "stable at " << i;  // trace order within a key
            }
        }
    }
}

TEST(RaySort, KeysGroupWhatTheyPromise) {
    Ray a, b;
    a.direction = Vec3(1, 1, 1);
    b.direction = Vec3(-1, 1, -1);
    EXPECT_EQ(ray_sort_key(a, RaySort::octant, Vec3(0), Vec3(1)), 0u);
    EXPECT_EQ(ray_sort_key(b, RaySort::octant, Vec3(0), Vec3(1)), 5u);
    // Morton: the lowest corner is 0, the highest all 30 bits.
    a.origin = Vec3(0), b.origin = Vec3(1);
    EXPECT_EQ(ray_sort_key(a, RaySort::morton, Vec3(0), Vec3(1)), 0u);
    EXPECT_EQ(ray_sort_key(b, RaySort::morton, Vec3(0), Vec3(1)), (1u << 30) - 1);
}

TEST(LineCoalescer, OneRequestPerDistinctLine) {
    LineCoalescer c(64);
    c.add(0, 64, DataKind::node);     // line 0
    c.add(0, 64, DataKind::node);     // the same node: merged
    c.add(96, 48, DataKind::triangle);  // lines 1 and 2
    c.add(128, 16, DataKind::triangle); // line 2 again
    std::vector<std::pair<uint64_t, uint32_t>> out;
    EXPECT_EQ(c.issue([&](uint64_t addr, uint32_t bytes, DataKind) { out.emplace_back(addr, bytes); }), 3u);
    EXPECT_EQ(out, (std::vector<std::pair<uint64_t, uint32_t>>{{0, 64}, {96, 32}, {128, 16}}));
    EXPECT_EQ(c.lane_requests(), 4u);
    EXPECT_EQ(c.requests(), 3u);
}

}  // namespace
