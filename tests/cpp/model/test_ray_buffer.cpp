// The treelet ray buffer on its own: admission up to capacity, overflow to memory with its traffic
// counted, every ray handed out exactly once, and the scheduler policies' choices.
#include <gtest/gtest.h>

#include <map>
#include <set>

#include "model_test_util.h"
#include "rtl_model/ray_buffer/ray_buffer.h"
#include "traces/accel/bvh2/bvh2.h"
#include "traces/bvh/builder.h"

using namespace rtsim;

namespace {

/// Dispatch stand-in: rays 0..n-1 in order.
class FakeDispatch : public sc_core::sc_module, public RaySourceIf {
public:
    FakeDispatch(sc_core::sc_module_name name, uint64_t n) : sc_core::sc_module(name), m_n(n) {}
    bool next_ray(uint32_t, RayJob* job) override {
        if (m_next == m_n) return false;
        job->id = m_next++;
        job->ray = Ray{Vec3(0.0f), 0.0f, Vec3(0.0f, 0.0f, 1.0f), 10.0f};
        return true;
    }
    uint64_t total_rays() const override { return m_n; }
    bool exhausted() const override { return m_next == m_n; }

private:
    uint64_t m_n, m_next = 0;
};

/// A partition of `treelets` treelets, one node each (node i in treelet i; node 0 is the root).
LocalityPartition partition_of(uint32_t treelets) {
    LocalityPartition p;
    p.budget_bytes = 64;
    for (uint32_t i = 0; i < treelets; ++i) {
        p.group_of.push_back(i);
        p.treelets.push_back(TreeletInfo{i, 1, 64, i ? 1u : 0u});
    }
    return p;
}

/// A one-triangle binary BVH: its steppers start every ray at node 0 (treelet 0).
std::unique_ptr<Accel> tiny_accel() {
    Scene scene;
    scene.triangles.push_back(Triangle{Vec3(0, 0, 5), Vec3(1, 0, 5), Vec3(0, 1, 5)});
    scene.materials.emplace_back();
    scene.tri_material.push_back(0);
    scene.tri_instance.push_back(0);
    return load_accel(bvh2_image(build_bvh(scene), BuildConfig{}, "binned"));
}

constexpr uint32_t kUnits = 2, kContexts = 16;

struct BufferBench {
    /// lookahead: how far past the asking time admission may issue reads (default: unbounded).
    BufferBench(const TreeletConfig& c, uint64_t rays, uint32_t treelets, const std::string& tag,
          Cycle lookahead = Cycle(1) << 40)
        : lookahead(lookahead),
          config(c),
          treelets(partition_of(treelets), nullptr),
          accel(tiny_accel()),
          map(accel->image().end_address(), rays, rays, 64, 8),
          steppers(*accel, StepOptions{}),
          dispatch(("dispatch_" + tag).c_str(), rays),
          memory(("memory_" + tag).c_str(), 100),
          buffer(("ray_buffer_" + tag).c_str(), config, this->treelets, map, steppers, kUnits, kContexts, kUnits,
                 ray_state_bytes(8, 8), lookahead) {
        buffer.rays(dispatch);
        buffer.mem(memory);
        kernel_elaborate();
    }
    void kernel_elaborate() { sc_core::sc_get_curr_simcontext()->elaborate(); }
    /// A unit's take at cycle t, after the admission engine has run up to t + lookahead (its
    /// process does that in a simulation; module tests have no sc_start).
    bool take(uint32_t unit, Cycle t, RayState* ray, uint32_t* treelet, Cycle* ready) {
        buffer.admit_until(t, t + lookahead);
        return buffer.take(unit, t, ray, treelet, ready);
    }
    Cycle lookahead;
    TreeletConfig config;  ///< the buffer keeps a reference, as to Top's config
    TreeletMap treelets;
    std::unique_ptr<Accel> accel;
    MemoryMap map;
    StepperPool steppers;
    FakeDispatch dispatch;
    test::FakeMemory memory;
    RayBuffer buffer;
};

TreeletConfig config_with(uint32_t buffer_kib, const std::string& policy, uint32_t threshold) {
    TreeletConfig c;
    c.enabled = true;
    c.buffer_kib = buffer_kib;
    EXPECT_TRUE(kTreeletPolicyChoices.parse(policy.c_str(), &c.policy));
    c.threshold = threshold;
    return c;
}

}  // namespace

TEST(RayBuffer, AdmitsUpToCapacityAndOverflowsParkedRays) {
    test::TestKernel kernel;
    TreeletConfig c = config_with(1, "largest", 1);  // 1 KiB: 8 rays of 120 bytes
    BufferBench b(c, 100, 4, "overflow");
    ASSERT_EQ(b.buffer.capacity_rays(), 1024u / 120u);
    const uint64_t capacity = b.buffer.capacity_rays();
    RayState ray;
    uint32_t treelet = 0;
    Cycle ready = 0;
    // The engine admits rays until the SRAM is full but one entry (kept for a unit that parks a
    // ray and takes the next in one step); take out as many rays as it holds.
    std::vector<RayState> held;
    for (uint64_t i = 0; i < capacity; ++i) {
        ASSERT_TRUE(b.take(0, 10, &ray, &treelet, &ready));
        EXPECT_EQ(treelet, 0u);
        EXPECT_EQ(ray.ray_id, i);
        held.push_back(std::move(ray));
    }
    EXPECT_EQ(b.buffer.max_occupancy(), capacity - 1);
    // The engine refills the SRAM (admission never overflows) and a take takes one: two free.
    ASSERT_TRUE(b.take(0, 20, &ray, &treelet, &ready));
    EXPECT_EQ(ray.ray_id, capacity);
    // Parking the held rays: two fit, the others overflow to memory as ray_buffer writes.
    for (RayState& r : held) b.buffer.park(2, std::move(r), 30);
    size_t overflow_writes = 0;
    for (const MemRequest& r : b.memory.requests) overflow_writes += r.write && r.kind == DataKind::ray_buffer;
    EXPECT_EQ(overflow_writes, capacity - 2);
    EXPECT_LE(b.buffer.max_occupancy(), b.buffer.capacity_rays());
    nlohmann::json s = b.buffer.stats_json();
    EXPECT_EQ(s["overflow_writes"].get<uint64_t>(), overflow_writes);
}

TEST(RayBuffer, AdmissionReadsAreStreamedNotBurst) {
    // Admitting a whole buffer of rays at one cycle: their ray-record reads leave one per cycle
    // with at most admit_outstanding in flight (a burst would swamp the L2's MSHRs).
    test::TestKernel kernel;
    TreeletConfig c = config_with(64, "largest", 1);  // 64 KiB: 546 rays
    c.admit_outstanding = 4;
    BufferBench b(c, 300, 4, "admission");
    RayState ray;
    uint32_t treelet = 0;
    Cycle ready = 0;
    ASSERT_TRUE(b.take(0, 1000, &ray, &treelet, &ready));
    std::vector<Cycle> issued;
    for (const MemRequest& r : b.memory.requests)
        if (r.kind == DataKind::ray) issued.push_back(r.time);
    ASSERT_EQ(issued.size(), 300u);  // every ray of the trace fits: all admitted
    EXPECT_EQ(issued.front(), 1000u);
    for (size_t i = 1; i < issued.size(); ++i) {
        EXPECT_GE(issued[i], issued[i - 1] + 1) << i;  // one per cycle
        if (i >= 4) {
            EXPECT_GE(issued[i], issued[i - 4] + 100) << i;  // the 5th waits for the 1st (latency 100)
        }
    }
    EXPECT_GE(ready, 1000u + 100u);
}

TEST(RayBuffer, AdmissionIssuesNoReadBeyondTheLookahead) {
    // With a lookahead of one cycle (the detailed level), the engine run at cycle t issues only the
    // reads that can leave by t + 1; later runs stream on from there, still one read per cycle with
    // at most admit_outstanding in flight, and every ray is admitted in the end.
    test::TestKernel kernel;
    TreeletConfig c = config_with(64, "largest", 1);
    c.admit_outstanding = 4;
    BufferBench b(c, 40, 4, "lookahead", 1);
    RayState ray;
    uint32_t treelet = 0;
    Cycle ready = 0;
    auto issued = [&] {
        std::vector<Cycle> t;
        for (const MemRequest& r : b.memory.requests)
            if (r.kind == DataKind::ray) t.push_back(r.time);
        return t;
    };
    ASSERT_TRUE(b.take(0, 1000, &ray, &treelet, &ready));
    ASSERT_EQ(issued().size(), 2u);  // cycles 1000 and 1001
    uint64_t taken = 1;
    for (Cycle t = 1001; taken < 40 && t < 100000; t += 7) {
        const size_t before = issued().size();
        while (b.take(0, t, &ray, &treelet, &ready)) {
            b.buffer.finished(t);
            ++taken;
        }
        const std::vector<Cycle> now = issued();
        for (size_t i = before; i < now.size(); ++i) EXPECT_LE(now[i], t + 1) << i;
    }
    EXPECT_EQ(taken, 40u);
    const std::vector<Cycle> all = issued();
    ASSERT_EQ(all.size(), 40u);
    for (size_t i = 1; i < all.size(); ++i) {
        EXPECT_GE(all[i], all[i - 1] + 1) << i;
        if (i >= 4) {
            EXPECT_GE(all[i], all[i - 4] + 100) << i;
        }
    }
}

TEST(RayBuffer, EveryRayIsHandedOutExactlyOnceUnderEveryPolicy) {
    for (const char* policy : {"largest", "oldest", "round_robin"}) {
        for (uint32_t kib : {1u, 64u}) {
            SCOPED_TRACE(std::string(policy) + " " + std::to_string(kib) + " KiB");
            test::TestKernel kernel;
            BufferBench b(config_with(kib, policy, 4), 300, 6, std::string(policy) + std::to_string(kib));
            // Each ray visits treelets 0, then 1..5 by id, then finishes: 2 takes per ray.
            std::map<uint64_t, int> takes;
            std::set<uint64_t> finished;
            RayState ray;
            uint32_t treelet = 0;
            Cycle ready = 0, now = 0;
            for (int guard = 0; guard < 100000 && !b.buffer.done(); ++guard, now += 3) {
                if (!b.take(guard % 2, now, &ray, &treelet, &ready)) continue;
                ++takes[ray.ray_id];
                if (treelet == 0) {
                    b.buffer.park(1 + ray.ray_id % 5, std::move(ray), now + 1);
                } else {
                    EXPECT_TRUE(finished.insert(ray.ray_id).second) << "ray " << ray.ray_id << " finished twice";
                    b.buffer.finished(now + 1);
                }
                EXPECT_LE(b.buffer.max_occupancy(), b.buffer.capacity_rays());
            }
            EXPECT_TRUE(b.buffer.done());
            EXPECT_EQ(finished.size(), 300u);
            for (const auto& [id, n] : takes) EXPECT_EQ(n, 2) << "ray " << id;
        }
    }
}

TEST(RayBuffer, LargestPolicyRunsTheLongestQueue) {
    test::TestKernel kernel;
    BufferBench b(config_with(64, "largest", 1), 10, 4, "largest");
    RayState ray;
    uint32_t treelet = 0;
    Cycle ready = 0;
    std::vector<RayState> rays;
    for (int i = 0; i < 10; ++i) {
        ASSERT_TRUE(b.take(0, 0, &ray, &treelet, &ready));
        rays.push_back(std::move(ray));
    }
    // 2 rays to treelet 1, 5 to treelet 2, 3 to treelet 3.
    for (int i = 0; i < 10; ++i) b.buffer.park(i < 2 ? 1 : i < 7 ? 2 : 3, std::move(rays[i]), 5);
    ASSERT_TRUE(b.take(1, 10, &ray, &treelet, &ready));
    EXPECT_EQ(treelet, 2u);
    EXPECT_GE(ready, 10u);  // state read from the SRAM after it was written
}
