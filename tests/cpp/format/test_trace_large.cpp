// Trace format at scale: millions of records written and streamed back in pieces, with memory
// bounded by the piece size rather than the trace size; throughput is printed.
#include <chrono>

#include <gtest/gtest.h>
#include <sys/resource.h>

#include "tests/cpp/format/format_test_util.h"
#include "traces/format/trace_reader.h"
#include "traces/format/trace_writer.h"

namespace rtsim {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
/// Peak resident set of this process so far, in MiB.
double peak_rss_mib() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_maxrss) / 1024.0;
}

TEST(TraceLarge, MillionsOfRecordsStreamWithBoundedMemory) {
    constexpr uint64_t kRays = 3'000'000, kBatch = 50'000;
    test::ScratchDir dir;
    const std::string path = dir.file("large.rtt");
    const double rss0 = peak_rss_mib();

    // Write rays, hits and work interleaved, batch by batch, as a tracer would.
    const auto t0 = std::chrono::steady_clock::now();
    {
        TraceWriter writer(path);
        std::vector<RayRecord> rays(kBatch);
        std::vector<HitRecord> hits(kBatch);
        std::vector<WorkRecord> work(kBatch);
        for (uint64_t base = 0; base < kRays; base += kBatch) {
            for (uint64_t i = 0; i < kBatch; ++i) {
                rays[i] = test::ray_at(base + i);
                hits[i] = test::hit_at(base + i);
                work[i] = test::work_at(base + i);
            }
            writer.append(SectionKind::rays, rays);
            writer.append(SectionKind::hits, hits);
            writer.append(SectionKind::work, work);
        }
        writer.close();
    }
    const double write_s = seconds_since(t0);
    const double mib = double(kRays * (40 + 20 + 20)) / (1 << 20);

    // Stream each section back in pieces that do not align with the 1 MiB chunks.
    const auto t1 = std::chrono::steady_clock::now();
    TraceReader reader(path);
    ASSERT_EQ(reader.section(SectionKind::rays).record_count, kRays);
    constexpr uint64_t kPiece = 33'333;
    std::vector<RayRecord> rays(kPiece);
    std::vector<HitRecord> hits(kPiece);
    std::vector<WorkRecord> work(kPiece);
    uint64_t mismatches = 0;
    for (uint64_t first = 0; first < kRays; first += kPiece) {
        const uint64_t n = std::min(kPiece, kRays - first);
        reader.read(SectionKind::rays, first, n, rays.data());
        reader.read(SectionKind::hits, first, n, hits.data());
        reader.read(SectionKind::work, first, n, work.data());
        // Spot-check three records per piece (a full compare would dominate the timing).
        for (uint64_t i : {uint64_t(0), n / 2, n - 1}) {
            const RayRecord r = test::ray_at(first + i);
            const HitRecord h = test::hit_at(first + i);
            mismatches += std::memcmp(&rays[i], &r, sizeof r) != 0;
            mismatches += std::memcmp(&hits[i], &h, sizeof h) != 0;
        }
    }
    const double read_s = seconds_since(t1);
    EXPECT_EQ(mismatches, 0u);
    EXPECT_EQ(work[(kRays - 1) % kPiece].steps, kRays - 1);

    const double rss_growth = peak_rss_mib() - rss0;
    std::printf("[ trace    ] %.0f MiB: write %.0f MiB/s (incl. close+fsync), read+verify %.0f MiB/s, "
                "peak RSS growth %.1f MiB\n",
                mib, mib / write_s, mib / read_s, rss_growth);
    // Spool buffers, copy buffer and the batches are a few MiB; the trace is 229 MiB.
    EXPECT_LT(rss_growth, 32.0) << "trace is " << mib << " MiB";
}

}  // namespace
}  // namespace rtsim
