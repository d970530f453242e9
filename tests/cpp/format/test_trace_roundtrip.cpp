// Trace format: record layouts, round trips of every section kind, empty sections and the
// writer's all-or-nothing output.
#include <cstddef>
#include <cstring>
#include <random>

#include <gtest/gtest.h>

#include "tests/cpp/format/format_test_util.h"
#include "traces/bvh/hw_layout.h"
#include "traces/common/error.h"
#include "traces/format/trace_layout.h"
#include "traces/format/trace_reader.h"
#include "traces/format/trace_writer.h"

namespace rtsim {
namespace {

using test::ScratchDir;

// Record layouts are part of the file format (docs/trace_format.md): check every offset.
TEST(TraceRecords, OffsetsMatchTheDocumentedLayout) {
    EXPECT_EQ(offsetof(RayRecord, origin), 0u);
    EXPECT_EQ(offsetof(RayRecord, tmin), 12u);
    EXPECT_EQ(offsetof(RayRecord, direction), 16u);
    EXPECT_EQ(offsetof(RayRecord, tmax), 28u);
    EXPECT_EQ(offsetof(RayRecord, pixel), 32u);
    EXPECT_EQ(offsetof(RayRecord, kind), 36u);
    EXPECT_EQ(offsetof(RayRecord, flags), 37u);
    EXPECT_EQ(offsetof(RayRecord, depth), 38u);
    EXPECT_EQ(offsetof(HitRecord, prim), 0u);
    EXPECT_EQ(offsetof(HitRecord, inst), 4u);
    EXPECT_EQ(offsetof(HitRecord, t), 8u);
    EXPECT_EQ(offsetof(HitRecord, u), 12u);
    EXPECT_EQ(offsetof(HitRecord, v), 16u);
    EXPECT_EQ(offsetof(WorkRecord, steps), 0u);
    EXPECT_EQ(offsetof(WorkRecord, box_tests), 4u);
    EXPECT_EQ(offsetof(WorkRecord, tri_tests), 8u);
    EXPECT_EQ(offsetof(WorkRecord, anyhit_calls), 12u);
    EXPECT_EQ(offsetof(WorkRecord, transforms), 16u);
    EXPECT_EQ(offsetof(WorkRecord, cell_steps), 20u);
    EXPECT_EQ(offsetof(WorkRecord, plane_tests), 24u);
    EXPECT_EQ(offsetof(WorkRecord, refs), 28u);
    EXPECT_EQ(offsetof(HwNode, bounds), 0u);
    EXPECT_EQ(sizeof(HwNode::bounds), 48u);
    EXPECT_EQ(offsetof(HwNode, child_ref), 48u);
    EXPECT_EQ(offsetof(HwNode, child_count), 56u);
    EXPECT_EQ(offsetof(HwTriangle, prim), 36u);
    EXPECT_EQ(offsetof(HwTriangle, inst), 40u);
    EXPECT_EQ(offsetof(HwTriangle, flags), 44u);
}

TEST(TraceRecords, SectionNamesAndSizes) {
    EXPECT_EQ(section_name(SectionKind::rays), "RAYS");
    EXPECT_EQ(section_name(SectionKind::accel), "ACCL");
    EXPECT_EQ(section_name(region_section(7)), "RG07");
    EXPECT_EQ(section_name(region_section(42)), "RG42");
    EXPECT_EQ(section_name(SectionKind(0x12345678)), "unknown");
    // The fourcc value spells the name in file byte order.
    const auto kind = static_cast<uint32_t>(region_section(13));
    EXPECT_EQ(std::memcmp(&kind, "RG13", 4), 0);
    uint32_t index = 0;
    EXPECT_TRUE(is_region_section(region_section(13), &index));
    EXPECT_EQ(index, 13u);
    EXPECT_FALSE(is_region_section(SectionKind::rays));
    EXPECT_EQ(section_record_bytes(SectionKind::rays), 40u);
    EXPECT_EQ(section_record_bytes(SectionKind::work), 40u);
    EXPECT_EQ(section_record_bytes(region_section(0)), 0u);  // regions: size from the descriptor
    EXPECT_EQ(section_record_bytes(SectionKind(0x12345678)), 0u);
}

TEST(TraceRecords, ConversionsRoundTrip) {
    Ray ray;
    ray.origin = Vec3(1.0f, -2.0f, 3.5f);
    ray.direction = Vec3(0.0f, 1.0f, -1.0f);
    ray.tmin = 0.001f;
    ray.tmax = 99.0f;
    const RayRecord r = to_record(ray, RayKind::shadow, 1234, 3, true);
    EXPECT_EQ(r.kind, uint8_t(RayKind::shadow));
    EXPECT_EQ(r.flags, kRayFlagAnyHit);
    EXPECT_EQ(r.pixel, 1234u);
    EXPECT_EQ(r.depth, 3u);
    const Ray back = ray_from_record(r);
    EXPECT_EQ(back.origin, ray.origin);
    EXPECT_EQ(back.direction, ray.direction);
    EXPECT_EQ(back.tmin, ray.tmin);
    EXPECT_EQ(back.tmax, ray.tmax);
    EXPECT_EQ(to_record(ray, RayKind::primary, 0, 0, false).flags, 0u);

    const Hit hit{42, 7, 2.5f, 0.25f, 0.5f};
    const Hit hb = hit_from_record(to_record(hit));
    EXPECT_EQ(hb.prim, 42);
    EXPECT_EQ(hb.inst, 7);
    EXPECT_EQ(hb.t, 2.5f);
    EXPECT_EQ(hb.u, 0.25f);
    EXPECT_EQ(hb.v, 0.5f);
}

// The WORK record is WorkCounts: each declared field at 4 x its position, reachable by name
// through the table the checker, the analytic level and the bindings iterate.
TEST(TraceRecords, WorkRecordIsTheDeclaredFieldsInOrder) {
    WorkCounts w;
    for (size_t i = 0; i < kWorkFields.size(); ++i) w[WorkField(i)] = uint32_t(10 + i);
    const auto* words = reinterpret_cast<const uint32_t*>(&w);
    for (size_t i = 0; i < kWorkFields.size(); ++i) {
        EXPECT_EQ(words[i], 10 + i) << kWorkFields[i].name;
        EXPECT_EQ(w.*kWorkFields[i].member, 10 + i) << kWorkFields[i].name;
    }
    EXPECT_EQ(w.steps, 10u);
    EXPECT_EQ(w.mailbox_hits, 10u + uint32_t(WorkField::mailbox_hits));
    EXPECT_EQ(w.*kWorkFields.back().member, 10u + kWorkFields.size() - 1);
    // The record holds the traced fields, in order; the model's own (the mailbox's) follow them
    // in WorkCounts and never reach a trace.
    EXPECT_EQ(sizeof(WorkRecord), kTracedWorkFieldCount * sizeof(uint32_t));
    const WorkRecord r = WorkRecord::of(w);
    const auto* record_words = reinterpret_cast<const uint32_t*>(&r);
    for (int i = 0; i < kTracedWorkFieldCount; ++i) EXPECT_TRUE(kWorkFields[size_t(i)].traced);
    for (int i = kTracedWorkFieldCount; i < kWorkFieldCount; ++i) EXPECT_FALSE(kWorkFields[size_t(i)].traced);
    for (int i = 0; i < kTracedWorkFieldCount; ++i) EXPECT_EQ(record_words[i], 10u + uint32_t(i));
    EXPECT_EQ(r.capsule_tests, 10u + uint32_t(kTracedWorkFieldCount) - 1);
    const WorkCounts back = r.counts();
    EXPECT_EQ(back.refs, w.refs);
    EXPECT_EQ(back.mailbox_lookups, 0u);
    EXPECT_EQ(back.mailbox_hits, 0u);
    EXPECT_EQ(work_field_of(OpKind::plane), WorkField::plane_tests);
    EXPECT_EQ(work_field_of(OpKind::box), WorkField::box_tests);
    WorkCounts twice = w;
    twice += w;
    EXPECT_EQ(twice.tri_tests, 2 * w.tri_tests);
    EXPECT_NE(twice, w);
}

/// Byte-exact equality of two record vectors.
template <class T>
bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

TEST(TraceRoundTrip, OlderWorkRecordsAreWidenedWithZeroSphereTests) {
    // A version-5 file: 32-byte WORK records (the fields before sphere_tests), over chunk ends.
    ScratchDir dir;
    const std::string path = dir.file("trace.rtt");
    struct WorkV5 {
        uint32_t field[kWorkRecordBytesV5 / 4];
    };
    std::vector<WorkV5> old(100);
    for (size_t i = 0; i < old.size(); ++i)
        for (uint32_t f = 0; f < kWorkRecordBytesV5 / 4; ++f) old[i].field[f] = uint32_t(100 * i + f + 1);
    // This build writes only 40-byte WORK records: the old ones go in under a kind of no fixed
    // size, relabelled WORK in the section table afterwards.
    const auto unsized = SectionKind(0x31313131);
    {
        TraceWriter writer(path, 200);
        writer.append(unsized, old);
        writer.close();
    }
    std::vector<uint8_t> bytes = test::read_bytes(path);
    tl::FileHeader h = tl::decode_header(bytes.data());
    SectionInfo entry = tl::decode_entry(&bytes[h.table_offset]);
    ASSERT_EQ(entry.kind, unsized);
    entry.kind = SectionKind::work;
    tl::encode_entry(entry, &bytes[h.table_offset]);
    const size_t n = h.table_bytes - 4;
    const uint32_t crc = tl::crc32_bytes(&bytes[h.table_offset], n);
    std::memcpy(&bytes[h.table_offset + n], &crc, 4);
    h.version = 5;
    tl::encode_header(h, bytes.data());
    test::write_bytes(path, bytes);
    TraceReader reader(path);
    EXPECT_EQ(reader.version(), 5u);
    EXPECT_EQ(reader.section(SectionKind::work).record_bytes, kWorkRecordBytesV5);
    std::vector<WorkRecord> got(60);
    reader.read(SectionKind::work, 30, 60, got.data());
    for (size_t i = 0; i < got.size(); ++i) {
        EXPECT_EQ(got[i].steps, uint32_t(100 * (30 + i) + 1)) << i;
        EXPECT_EQ(got[i].refs, uint32_t(100 * (30 + i) + 8)) << i;
        EXPECT_EQ(got[i].sphere_tests, 0u) << i;
        EXPECT_EQ(got[i].capsule_tests, 0u) << i;
    }
    // The same 32-byte records under version 6 are refused, naming the size this build expects.
    h.version = 6;
    tl::encode_header(h, bytes.data());
    test::write_bytes(path, bytes);
    try {
        TraceReader again(path);
        FAIL() << "32-byte WORK records accepted as version 6";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("has 32-byte records, this build expects 40"), std::string::npos) << e.what();
    }
}

TEST(TraceRoundTrip, InterleavedAppendsOfAllKindsAcrossManyChunks) {
    ScratchDir dir;
    const std::string path = dir.file("trace.rtt");
    std::vector<RayRecord> rays;
    std::vector<HitRecord> hits;
    std::vector<WorkRecord> work;
    std::vector<HwNode> nodes;
    std::vector<HwTriangle> tris;
    // Random batch sizes and an interleaving that touches every kind many times.
    std::mt19937 rng(7);
    {
        TraceWriter writer(path, 256);
        for (int step = 0; step < 600; ++step) {
            const uint64_t n = rng() % 40;
            const uint64_t base = rays.size();
            std::vector<RayRecord> r;
            std::vector<HitRecord> h;
            std::vector<WorkRecord> w;
            for (uint64_t i = 0; i < n; ++i) {
                r.push_back(test::ray_at(base + i));
                h.push_back(test::hit_at(base + i));
                w.push_back(test::work_at(base + i));
            }
            writer.append(SectionKind::rays, r);
            if (step % 3 == 0) {
                HwNode node{};
                node.child_ref[0] = uint32_t(step);
                node.lo(1, 2) = float(step);
                nodes.push_back(node);
                writer.append(region_section(0), std::vector<HwNode>{node});
            }
            writer.append(SectionKind::hits, h);
            HwTriangle tri{};
            tri.prim = uint32_t(step);
            tri.v2[1] = -float(step);
            tris.push_back(tri);
            writer.append(region_section(1), &tri, 1, sizeof tri);
            writer.append(SectionKind::work, w);
            rays.insert(rays.end(), r.begin(), r.end());
            hits.insert(hits.end(), h.begin(), h.end());
            work.insert(work.end(), w.begin(), w.end());
        }
        writer.close();
    }
    EXPECT_EQ(dir.listing(), std::vector<std::string>{"trace.rtt"});

    TraceReader reader(path);
    EXPECT_EQ(reader.version(), kTraceVersion);
    ASSERT_EQ(reader.sections().size(), 5u);
    EXPECT_EQ(reader.sections()[0].kind, SectionKind::rays);  // order of first append
    EXPECT_EQ(reader.sections()[1].kind, region_section(0));
    const std::vector<uint8_t> file = test::read_bytes(path);
    for (const SectionInfo& s : reader.sections()) {
        EXPECT_EQ(s.offset % 64, 0u);
        EXPECT_EQ(s.bytes, s.record_bytes * s.record_count);
        EXPECT_EQ(s.chunk_bytes, 256u);
        EXPECT_LE(s.offset + s.bytes, file.size());
    }
    EXPECT_GT(reader.section(SectionKind::rays).bytes / 256, 100u);  // many chunks
    EXPECT_TRUE(same_bytes(reader.read_all<RayRecord>(SectionKind::rays), rays));
    EXPECT_TRUE(same_bytes(reader.read_all<HitRecord>(SectionKind::hits), hits));
    EXPECT_TRUE(same_bytes(reader.read_all<WorkRecord>(SectionKind::work), work));
    EXPECT_TRUE(same_bytes(reader.read_all<HwNode>(region_section(0)), nodes));
    EXPECT_TRUE(same_bytes(reader.read_all<HwTriangle>(region_section(1)), tris));
    // The payload is the records verbatim at the section's offset (what np.memmap relies on).
    const SectionInfo& rs = reader.section(SectionKind::rays);
    EXPECT_EQ(std::memcmp(file.data() + rs.offset, rays.data(), rs.bytes), 0);
    reader.verify_all();
}

TEST(TraceRoundTrip, RandomSubrangesFromAFreshReader) {
    ScratchDir dir;
    const std::string path = dir.file("t.rtt");
    std::vector<HitRecord> hits;
    for (uint64_t i = 0; i < 5000; ++i) hits.push_back(test::hit_at(i));
    {
        TraceWriter writer(path, 300);  // chunks not a multiple of the record size
        writer.append(SectionKind::hits, hits);
        writer.close();
    }
    TraceReader reader(path);
    std::mt19937 rng(3);
    for (int k = 0; k < 300; ++k) {
        const uint64_t first = rng() % 5000, count = rng() % (5000 - first + 1);
        std::vector<HitRecord> part(count);
        reader.read(SectionKind::hits, first, count, part.data());
        ASSERT_EQ(std::memcmp(part.data(), hits.data() + first, count * sizeof(HitRecord)), 0) << first;
    }
    const std::string msg = test::error_of([&] { reader.read(SectionKind::hits, 4990, 11, hits.data()); });
    EXPECT_NE(msg.find("out of range"), std::string::npos) << msg;
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
}

TEST(TraceRoundTrip, EmptySectionsAndEmptyTraces) {
    ScratchDir dir;
    const std::string path = dir.file("empty.rtt");
    {
        TraceWriter writer(path, 256);
        writer.append(SectionKind::rays, nullptr, 0, sizeof(RayRecord));
        writer.append(SectionKind::hits, std::vector<HitRecord>{});
        writer.append(SectionKind::work, std::vector<WorkRecord>{test::work_at(1)});
        writer.close();
    }
    TraceReader reader(path);
    ASSERT_EQ(reader.sections().size(), 3u);
    EXPECT_TRUE(reader.has(SectionKind::rays));
    EXPECT_EQ(reader.section(SectionKind::rays).record_count, 0u);
    EXPECT_TRUE(reader.read_all<RayRecord>(SectionKind::rays).empty());
    EXPECT_TRUE(reader.read_all<HitRecord>(SectionKind::hits).empty());
    EXPECT_EQ(reader.read_all<WorkRecord>(SectionKind::work).size(), 1u);
    reader.verify_all();

    // A trace with no sections at all is valid; asking for one names what is missing.
    const std::string none = dir.file("none.rtt");
    TraceWriter(none).close();
    TraceReader empty(none);
    EXPECT_TRUE(empty.sections().empty());
    EXPECT_FALSE(empty.has(SectionKind::rays));
    const std::string msg = test::error_of([&] { empty.section(SectionKind::rays); });
    EXPECT_NE(msg.find("no section RAYS"), std::string::npos) << msg;
}

TEST(TraceWriterSafety, DestroyedWithoutCloseLeavesNothingAndKeepsExistingOutput) {
    ScratchDir dir;
    const std::string path = dir.file("trace.rtt");
    test::write_bytes(path, {'k', 'e', 'e', 'p'});
    {
        TraceWriter writer(path, 256);
        std::vector<RayRecord> rays(10000, test::ray_at(5));
        writer.append(SectionKind::rays, rays);
        writer.append(SectionKind::hits, std::vector<HitRecord>(100));
        EXPECT_GE(dir.listing().size(), 3u);  // OUT + two spools while writing
    }
    EXPECT_EQ(dir.listing(), std::vector<std::string>{"trace.rtt"});
    EXPECT_EQ(test::read_bytes(path), (std::vector<uint8_t>{'k', 'e', 'e', 'p'}));

    // Without an existing output nothing at all remains.
    const std::string other = dir.file("other.rtt");
    { TraceWriter(other).append(SectionKind::work, std::vector<WorkRecord>(3)); }
    EXPECT_EQ(dir.listing(), std::vector<std::string>{"trace.rtt"});

    // A successful close replaces the old file atomically.
    TraceWriter writer(path);
    writer.append(SectionKind::hits, std::vector<HitRecord>(4));
    writer.close();
    EXPECT_EQ(TraceReader(path).section(SectionKind::hits).record_count, 4u);
    EXPECT_EQ(dir.listing(), std::vector<std::string>{"trace.rtt"});
}

TEST(TraceWriterSafety, RejectsMisuseWithTheFileInTheMessage) {
    ScratchDir dir;
    const std::string path = dir.file("t.rtt");
    TraceWriter writer(path);
    std::string msg = test::error_of([&] { writer.append(SectionKind::rays, std::vector<HitRecord>(1)); });
    EXPECT_NE(msg.find("RAYS needs 40-byte records"), std::string::npos) << msg;
    const uint32_t custom = 0x54534554;  // 'TEST': a kind this build does not know
    writer.append(SectionKind(custom), std::vector<uint64_t>(2));
    msg = test::error_of([&] { writer.append(SectionKind(custom), std::vector<uint32_t>(2)); });
    EXPECT_NE(msg.find("TEST has 8-byte records"), std::string::npos) << msg;
    writer.close();
    msg = test::error_of([&] { writer.append(SectionKind::hits, std::vector<HitRecord>(1)); });
    EXPECT_NE(msg.find("after close"), std::string::npos) << msg;
    // Unknown kinds survive a round trip (a newer writer's extra section).
    EXPECT_EQ(TraceReader(path).section(SectionKind(custom)).record_count, 2u);

    const std::string bad = dir.file("no_such_folder/t.rtt");
    msg = test::error_of([&] { TraceWriter(bad).append(SectionKind::hits, std::vector<HitRecord>(1)); });
    EXPECT_NE(msg.find(bad), std::string::npos) << msg;
}

}  // namespace
}  // namespace rtsim
