// Harness pieces: the latency histogram, the reference window over a trace file, and the hit
// comparison the checker applies to every ray.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include <unistd.h>

#include "sim/harness/hit_checker.h"
#include "sim/harness/latency_histogram.h"
#include "sim/harness/trace_stream.h"
#include "traces/format/trace_writer.h"
#include "model_test_util.h"

namespace rtsim {
namespace {

using test::error_of;

/// (upper bound, rays) of the single bucket a histogram of equal values has.
std::pair<uint64_t, uint64_t> only_bucket(const LatencyHistogram& h) {
    const nlohmann::json j = h.to_json()["histogram"];
    EXPECT_EQ(j["bucket_upper_cycles"].size(), 1u);
    return {j["bucket_upper_cycles"][0], j["rays"][0]};
}

TEST(LatencyHistogram, BucketBoundsAreInclusiveAndWithinAnEighth) {
    for (uint64_t v : {0ull, 1ull, 7ull, 8ull, 9ull, 15ull, 16ull, 17ull, 100ull, 1000ull, 4095ull, 4096ull,
                       123456789ull, 1ull << 40}) {
        LatencyHistogram h;
        h.add(v);
        const uint64_t upper = only_bucket(h).first;
        EXPECT_GE(upper, v) << v;
        EXPECT_LE(double(upper), double(v) * 1.125 + 1) << v;
        // The bound belongs to the bucket it bounds: adding it lands in the same bucket.
        h.add(upper);
        EXPECT_EQ(only_bucket(h).second, 2u) << "value " << v << ", bucket upper bound " << upper;
    }
}

TEST(LatencyHistogram, MeanMaxAndQuantiles) {
    LatencyHistogram h;
    for (uint64_t v = 1; v <= 1000; ++v) h.add(v);
    EXPECT_EQ(h.count(), 1000u);
    EXPECT_DOUBLE_EQ(h.mean(), 500.5);
    EXPECT_EQ(h.max(), 1000u);
    EXPECT_GE(h.quantile(0.5), 500u);
    EXPECT_LE(h.quantile(0.5), 500u * 1.125 + 1);
    EXPECT_GE(h.quantile(0.99), 990u);
    EXPECT_LE(h.quantile(0.99), 1000u);  // never above the max
    EXPECT_EQ(h.quantile(1.0), 1000u);
    EXPECT_LE(h.quantile(0.5), h.quantile(0.95));
    const nlohmann::json j = h.to_json();
    uint64_t rays = 0;
    for (const auto& n : j["histogram"]["rays"]) rays += n.get<uint64_t>();
    EXPECT_EQ(rays, 1000u);
    EXPECT_EQ(j["rays"], 1000);
    EXPECT_EQ(j["max_cycles"], 1000);
    LatencyHistogram empty;
    EXPECT_EQ(empty.mean(), 0.0);
    EXPECT_EQ(empty.quantile(0.5), 0u);
}

/// A trace file of `n` rays whose reference hit of ray i has prim i and t = i.
class SmallTrace {
public:
    explicit SmallTrace(uint64_t n) {
        static int counter = 0;
        m_path = (std::filesystem::temp_directory_path() /
                  ("rtsim_model_" + std::to_string(::getpid()) + "_" + std::to_string(counter++) + ".rtt"))
                     .string();
        std::vector<RayRecord> rays(n);
        std::vector<HitRecord> hits(n);
        std::vector<WorkRecord> work(n);
        for (uint64_t i = 0; i < n; ++i) {
            rays[i] = RayRecord{};
            hits[i] = HitRecord{int32_t(i), -1, float(i), 0.0f, 0.0f};
            work[i] = WorkRecord{uint32_t(i), uint32_t(2 * i), 0, 0, 0, 0, 0, 0};
        }
        TraceWriter w(m_path, 64);
        w.append(SectionKind::rays, rays);
        w.append(SectionKind::hits, hits);
        w.append(SectionKind::work, work);
        w.close();
    }
    ~SmallTrace() { std::remove(m_path.c_str()); }
    const std::string& path() const { return m_path; }

private:
    std::string m_path;
};

TEST(ReferenceWindow, RetiresCheckedChunksAndStaysBounded) {
    SmallTrace trace(1000);
    TraceReader reader(trace.path());
    ReferenceWindow window(reader, 16);
    size_t most = 0;
    // Rays complete out of order within 24 rays in flight (a window over 2-3 chunks).
    for (uint64_t base = 0; base < 1000; base += 24) {
        for (uint64_t k = 0; k < 24; ++k) {
            const uint64_t id = base + (k * 7) % 24;  // a permutation of base..base+23
            if (id >= 1000) continue;
            EXPECT_EQ(window.hit(id).prim, int32_t(id));
            EXPECT_EQ(window.work(id).box_tests, 2 * id);
            window.checked(id);
            most = std::max(most, window.resident_chunks());
        }
    }
    EXPECT_LE(most, 3u) << "only the chunks of rays in flight stay resident";
    EXPECT_EQ(window.resident_chunks(), 0u) << "every chunk retires once all its rays are checked";
}

TEST(ReferenceWindow, RefusesRetiredAndOutOfRangeRays) {
    SmallTrace trace(100);
    TraceReader reader(trace.path());
    ReferenceWindow window(reader, 10);
    for (uint64_t id = 0; id < 10; ++id) window.checked(id);
    EXPECT_EQ(window.resident_chunks(), 0u);
    EXPECT_EQ(window.hit(20).prim, 20);  // loads chunks 1 and 2
    EXPECT_NE(error_of([&] { window.hit(3); }).find("after all rays of its chunk were checked"), std::string::npos);
    EXPECT_NE(error_of([&] { window.hit(100); }).find("beyond the trace"), std::string::npos);
}

TEST(ReferenceWindow, KeepsEarlierChunksWhenALaterRayFinishesFirst) {
    // All loaded chunks retired, then a ray two chunks ahead finishes before any ray of the
    // chunk between (many rays in flight, chunks of few rays): that chunk must still be found.
    SmallTrace trace(100);
    TraceReader reader(trace.path());
    ReferenceWindow window(reader, 10);
    for (uint64_t id = 0; id < 10; ++id) {
        EXPECT_EQ(window.hit(id).prim, int32_t(id));
        window.checked(id);
    }
    EXPECT_EQ(window.hit(25).prim, 25);
    window.checked(25);
    EXPECT_EQ(window.hit(15).prim, 15);
    window.checked(15);
    for (uint64_t id = 10; id < 100; ++id) {
        if (id == 15 || id == 25) continue;
        EXPECT_EQ(window.hit(id).prim, int32_t(id));
        window.checked(id);
    }
    EXPECT_EQ(window.resident_chunks(), 0u);
}

TEST(HitChecker, ComparesPrimitiveTheBitsOfTAndWork) {
    RayResult r;
    r.hit.prim = 5;
    r.hit.t = 2.5f;
    r.work = WorkCounts{3, 6, 4, 0, 0};
    HitRecord ref{5, -1, 2.5f, 0.1f, 0.2f};
    WorkRecord work{3, 6, 4, 0, 0, 0, 0, 0};
    bool hit_differs = true;
    EXPECT_EQ(compare_with_reference(r, ref, work, &hit_differs), "");
    EXPECT_FALSE(hit_differs);

    HitRecord off_by_one_ulp = ref;
    off_by_one_ulp.t = std::nextafter(2.5f, 3.0f);
    EXPECT_NE(compare_with_reference(r, off_by_one_ulp, work, &hit_differs), "");
    EXPECT_TRUE(hit_differs);

    HitRecord other_prim = ref;
    other_prim.prim = 6;
    EXPECT_NE(compare_with_reference(r, other_prim, work, &hit_differs).find("reference prim 6"), std::string::npos);
    EXPECT_TRUE(hit_differs);

    WorkRecord more_tests = work;
    more_tests.tri_tests = 5;
    std::string diff = compare_with_reference(r, ref, more_tests, &hit_differs);
    EXPECT_NE(diff.find("work"), std::string::npos) << diff;
    EXPECT_FALSE(hit_differs);

    // Two misses agree whatever their t.
    RayResult miss;
    HitRecord ref_miss{-1, -1, INFINITY, 0, 0};
    EXPECT_EQ(compare_with_reference(miss, ref_miss, WorkRecord{}, &hit_differs), "");
}

}  // namespace
}  // namespace rtsim
