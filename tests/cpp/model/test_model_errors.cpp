// Model failures and memory: a SystemC-wrapped error becomes a message naming the
// trace and ray; the memory estimate refuses absurd configs with the figure.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>

#include "sim/harness/memory_estimate.h"
#include "sim/harness/model_errors.h"
#include "tests/cpp/model/model_test_util.h"
#include "traces/format/trace_writer.h"
#include "traces/common/error.h"

namespace rtsim {
namespace {

TEST(ModelErrors, UnwrapReport) {
    const std::string report =
        "Error: (E549) uncaught exception: traversal stack overflow (64 entries): BVH deeper\n"
        "In file: kernel/sc_except.cpp:101\nIn process: top.unit0.run @ 12 ns";
    EXPECT_EQ(unwrap_report(report), "traversal stack overflow (64 entries): BVH deeper");
    EXPECT_EQ(unwrap_report("plain message"), "plain message");
}

/// A structure whose traversal fails on rays aimed along +z from the origin column (as a
/// corrupt image the loader could not see through would fail deep in traversal).
class FailingAccel final : public Accel {
public:
    explicit FailingAccel(bool fail) : Accel(AccelImage{}), m_fail(fail) {}
    std::unique_ptr<Stepper> make_stepper(const StepOptions&) const override { return nullptr; }
    Hit trace(const Ray& ray, TraversalMode, WorkCounts*, const StepOptions&) const override {
        if (m_fail && ray.origin.x == 0.0f) throw Error("traversal stack overflow (64 entries)");
        return Hit{};
    }
    LocalityPartition partition(uint64_t) const override { return {}; }
    std::vector<OpKind> op_kinds() const override { return {}; }
    uint32_t max_stack_entries() const override { return 64; }

private:
    bool m_fail;
};

TEST(ModelErrors, FirstFailingRayIsNamed) {
    const std::string path = (std::filesystem::temp_directory_path() /
                              ("rtsim_model_errors_" + std::to_string(::getpid()) + ".rtt")).string();
    {
        TraceWriter w(path);
        // Ray 0 traverses; ray 1 makes the traversal throw.
        std::vector<RayRecord> rays = {
            to_record(Ray{Vec3(5.0f, 5.0f, -5.0f), 0.0f, Vec3(0.0f, 0.0f, 1.0f), 100.0f}, RayKind::primary, 0, 0, false),
            to_record(Ray{Vec3(0.0f, 0.0f, -5.0f), 0.0f, Vec3(0.0f, 0.0f, 1.0f), 100.0f}, RayKind::primary, 1, 0, false)};
        w.append(SectionKind::rays, rays);
        w.close();
    }
    TraceReader reader(path);
    const std::string msg = first_failing_ray(FailingAccel(true), reader);
    EXPECT_EQ(msg.rfind("ray 1: traversal stack overflow", 0), 0u) << msg;
    // A structure that traverses every ray: nothing to name.
    TraceReader again(path);
    EXPECT_EQ(first_failing_ray(FailingAccel(false), again), "");
    std::filesystem::remove(path);
}

TEST(ModelErrors, MemoryEstimateRefusesAbsurdConfigs) {
    setenv("RTSIM_SIM_MEMORY_LIMIT_MIB", "8192", 1);
    SimConfig config;
    EXPECT_EQ(test::error_of([&] { check_sim_memory(config, 160000, "cfg.json"); }), "");
    const MemoryEstimate small = estimate_sim_memory(config, 160000);
    EXPECT_LT(small.bytes, uint64_t(64) << 20);  // the default model is tens of MB
    config.traversal.units = 4096;
    config.traversal.ray_contexts = 4096;
    const MemoryEstimate big = estimate_sim_memory(config, 160000);
    EXPECT_GT(big.bytes, uint64_t(16) << 30);  // 16.7 M contexts at about 1.1 KiB
    const std::string msg = test::error_of([&] { check_sim_memory(config, 160000, "cfg.json"); });
    EXPECT_EQ(msg.rfind("cfg.json: the model for this config needs about 18.", 0), 0u) << msg;
    EXPECT_NE(msg.find("limit 8.0 GiB"), std::string::npos) << msg;
    EXPECT_NE(msg.find("16777216 ray contexts"), std::string::npos) << msg;
    // The functional level builds no model: the same config is fine there.
    config.fidelity = Fidelity::functional;
    EXPECT_EQ(test::error_of([&] { check_sim_memory(config, 160000, "cfg.json"); }), "");
    unsetenv("RTSIM_SIM_MEMORY_LIMIT_MIB");
}

}  // namespace
}  // namespace rtsim
