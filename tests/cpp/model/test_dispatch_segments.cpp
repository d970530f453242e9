// The dispatch's dealer over a stream cut into segments (a sampled run's clusters): the next
// segment is read only once every ray of the previous one has been handed out, every ray is
// handed out once, and the dealer is exhausted only at the stream's end.
#include <gtest/gtest.h>

#include <set>
#include <vector>

#include "model_test_util.h"
#include "rtl_model/dispatch/dispatch.h"

using namespace rtsim;

namespace {

/// Segments of consecutive ray ids; records how many rays the dealer had handed out when each
/// segment was first read (what a sampled run's functional warming would see).
class SegmentedStream : public RayStream {
public:
    SegmentedStream(std::vector<uint64_t> sizes, const uint64_t& handed)
        : m_sizes(std::move(sizes)), m_handed(handed) {
        for (uint64_t s : m_sizes) m_total += s;
    }
    size_t read_chunk(size_t max, std::vector<RayJob>* out) override {
        if (m_segment >= m_sizes.size() || m_segment != m_open) return 0;
        if (m_in_segment == 0) first_read_after.push_back(m_handed);
        const size_t n = size_t(std::min<uint64_t>(max, m_sizes[m_segment] - m_in_segment));
        for (size_t i = 0; i < n; ++i) out->push_back(RayJob{m_next_id++, Ray{}, false, 0});
        m_in_segment += n;
        if (m_in_segment == m_sizes[m_segment]) ++m_segment, m_in_segment = 0;
        return n;
    }
    uint64_t total_rays() const override { return m_total; }
    bool next_segment() override {
        if (m_segment >= m_sizes.size()) return false;
        m_open = m_segment;
        return true;
    }
    std::vector<uint64_t> first_read_after;

private:
    std::vector<uint64_t> m_sizes;
    const uint64_t& m_handed;
    uint64_t m_total = 0, m_next_id = 0, m_in_segment = 0;
    size_t m_segment = 0, m_open = 0;
};

/// Requests rays until none is left, unit 0 asking as often as the others together (so the
/// per-unit queues drain unevenly); returns the ids in hand-out order. The dealer must not say it
/// is exhausted before the last of the stream's `total` rays is out (a unit would stop).
std::vector<uint64_t> drain(RayDealer& dealer, uint32_t units, uint64_t total, uint64_t* handed) {
    std::vector<uint64_t> ids;
    for (uint64_t turn = 0;; ++turn) {
        const uint32_t unit = turn % 2 == 0 ? 0u : uint32_t(1 + (turn / 2) % (units - 1));
        RayJob job;
        if (!dealer.next_ray(unit, &job)) break;
        ids.push_back(job.id);
        ++*handed;
        if (ids.size() < total) {
            EXPECT_FALSE(dealer.exhausted()) << "after ray " << ids.size();
        }
    }
    return ids;
}

void expect_segments_in_order(DispatchPolicy policy) {
    DispatchConfig config;
    config.policy = policy;
    config.chunk_rays = 5;  // segments span several chunks
    const uint32_t units = 4;
    const std::vector<uint64_t> sizes = {23, 17, 9};
    uint64_t handed = 0;
    SegmentedStream stream(sizes, handed);
    RayDealer dealer(config, units, stream);
    const std::vector<uint64_t> ids = drain(dealer, units, 49, &handed);
    EXPECT_TRUE(dealer.exhausted());
    ASSERT_EQ(ids.size(), 49u);
    EXPECT_EQ(std::set<uint64_t>(ids.begin(), ids.end()).size(), 49u);  // each ray once
    // Each segment is first read after every ray of the segments before it was handed out.
    EXPECT_EQ(stream.first_read_after, (std::vector<uint64_t>{0, 23, 40}));
    // So no ray of a later segment is handed out before the last ray of an earlier one.
    for (size_t i = 1; i < ids.size(); ++i) {
        const auto segment = [&](uint64_t id) { return id < 23 ? 0 : id < 40 ? 1 : 2; };
        EXPECT_LE(segment(ids[i - 1]), segment(ids[i])) << "at position " << i;
    }
}

TEST(DispatchSegments, InterleavedReadsTheNextSegmentOnlyWhenEveryRayIsOut) {
    expect_segments_in_order(DispatchPolicy::interleaved);
}

TEST(DispatchSegments, OnDemandReadsTheNextSegmentOnlyWhenEveryRayIsOut) {
    expect_segments_in_order(DispatchPolicy::on_demand);
}

}  // namespace

// Leading empty frames (an animated trace whose first frames hold no rays) end at once, each
// through the barrier set before the frames (a moving scene's build of the next frame), in order,
// each release the next one's start; their end hooks see those releases.
TEST(DispatchFrames, LeadingEmptyFramesPassTheirBarriersInOrder) {
    rtsim::test::TestKernel kernel;
    DispatchConfig config;
    uint64_t handed = 0;
    SegmentedStream stream({5}, handed);
    Dispatch dispatch("dispatch", config, 2, stream);
    std::vector<std::pair<uint32_t, Cycle>> barriers, ends;
    std::vector<uint32_t> begins;
    dispatch.set_barrier([&](uint32_t f, Cycle at) {
        barriers.push_back({f, at});
        return at + 100;  // the build takes 100 cycles
    });
    dispatch.set_frames({0, 0, 5}, [&](uint32_t f, Cycle at) { ends.push_back({f, at}); },
                        [&](uint32_t f) { begins.push_back(f); });
    EXPECT_EQ(barriers, (std::vector<std::pair<uint32_t, Cycle>>{{0, 0}, {1, 100}}));
    EXPECT_EQ(ends, (std::vector<std::pair<uint32_t, Cycle>>{{0, 100}, {1, 200}}));
    EXPECT_EQ(begins, (std::vector<uint32_t>{0, 1, 2}));
}
