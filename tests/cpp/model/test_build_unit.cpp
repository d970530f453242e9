// The build unit stepped (build_unit.h): a build issued in steps, as the build streamer issues
// it beside the traversal, makes the requests a build issued at once makes, at the same cycles;
// and the frame build schedule (sim/harness/frame_builds.h) orders builds at the barriers or
// beside the previous frame's rays.
#include <gtest/gtest.h>

#include <vector>

#include "rtl_model/build_unit/build_unit.h"
#include "sim/harness/frame_builds.h"

namespace rtsim {
namespace {

/// A memory whose lines take a fixed latency; it logs every request.
class FixedLatency : public MemIf {
public:
    Cycle access(const MemRequest& req) override {
        log.push_back({req.addr, req.time, req.write});
        return req.time + 100;
    }
    struct Entry {
        uint64_t addr;
        Cycle time;
        bool write;
        bool operator==(const Entry& o) const { return addr == o.addr && time == o.time && write == o.write; }
    };
    std::vector<Entry> log;
};

std::vector<BuildJob> two_jobs() {
    BuildJob rebuild;
    rebuild.triangles = 1000;
    rebuild.reads = {{0x10000, 64 * 40}};
    rebuild.writes = {{0x80000, 64 * 30}, {0x90000, 100}};
    BuildJob refit;
    refit.refit = true;
    refit.tree_nodes = 500;
    refit.reads = {{0x20000, 64 * 10}};
    refit.writes = {{0xA0000, 64 * 12}};
    return {rebuild, refit};
}

TEST(BuildUnit, AStepwiseBuildIssuesWhatABuildAtOnceIssues) {
    BuildUnitConfig config;
    config.outstanding_lines = 4;
    const std::vector<BuildJob> jobs = two_jobs();
    FixedLatency at_once_mem, stepped_mem;
    BuildUnit at_once(config, at_once_mem, 64), stepped(config, stepped_mem, 64);
    const FrameBuild a = at_once.run(jobs, 500);
    stepped.begin(jobs, 500);
    uint64_t steps = 0;
    for (Cycle t = 500; stepped.has_requests(); t += 37, ++steps) {
        EXPECT_GE(stepped.next_issue(), stepped_mem.log.empty() ? 500 : stepped_mem.log.back().time);
        stepped.issue_until(t);
        for (const auto& e : stepped_mem.log) EXPECT_LE(e.time, t);  // nothing issued ahead
    }
    const FrameBuild b = stepped.finish();
    EXPECT_GT(steps, 10u);
    EXPECT_EQ(at_once_mem.log, stepped_mem.log);
    EXPECT_EQ(a.end, b.end);
    EXPECT_EQ(a.read_bytes, b.read_bytes);
    EXPECT_EQ(a.written_bytes, b.written_bytes);
    EXPECT_EQ(at_once.stats_json(), stepped.stats_json());
    // Three read passes of the rebuild, one of the refit, then their writes: 40 x 3 + 10 reads.
    EXPECT_EQ(a.read_bytes, 64u * (40 * 3 + 10));
}

TEST(FrameBuildSchedule, AtTheBarrierOrBesideThePreviousFramesRays) {
    // Each frame's build takes 100 cycles; the log records (frame, start).
    std::vector<std::pair<uint32_t, Cycle>> started;
    std::vector<Cycle> done(4, 0);
    auto start = [&](uint32_t f, Cycle at) { started.push_back({f, at}), done[f] = at + 100; };
    auto finish = [&](uint32_t f) { return done[f]; };
    {
        FrameBuildSchedule serial(false, 4, start, finish);
        EXPECT_TRUE(started.empty());
        EXPECT_EQ(serial.ready(1, 30), 130u);  // built after frame 0's 30 cycles
        EXPECT_EQ(serial.ready(2, 200), 300u);
        EXPECT_EQ(started, (std::vector<std::pair<uint32_t, Cycle>>{{1, 30}, {2, 200}}));
    }
    started.clear();
    FrameBuildSchedule overlap(true, 4, start, finish);
    EXPECT_EQ(started, (std::vector<std::pair<uint32_t, Cycle>>{{1, 0}}));  // beside frame 0
    EXPECT_EQ(overlap.ready(1, 30), 100u);   // frame 0 ends first: frame 1 waits for its build
    EXPECT_EQ(overlap.ready(2, 350), 350u);  // frame 2's build (from 100) was done at 200
    EXPECT_EQ(overlap.ready(3, 400), 450u);  // frame 3's build started with frame 2, at 350
    EXPECT_EQ(started, (std::vector<std::pair<uint32_t, Cycle>>{{1, 0}, {2, 100}, {3, 350}}));
    EXPECT_EQ(overlap.ready(4, 600), 600u);  // no frame 4: nothing to build
}

}  // namespace
}  // namespace rtsim
