// Trace format: truncated, bit-flipped, wrong-version and foreign files are refused with a
// message naming the file and the damaged part (header, section table, section and chunk).
#include <gtest/gtest.h>

#include "tests/cpp/format/format_test_util.h"
#include "traces/format/trace_layout.h"
#include "traces/format/trace_reader.h"
#include "traces/format/trace_writer.h"

namespace rtsim {
namespace {

namespace tl = trace_layout;
using test::error_of;

bool contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

/// A small trace with three sections of many 256-byte chunks, and its bytes.
class CorruptionTest : public ::testing::Test {
protected:
    void SetUp() override {
        m_good = m_dir.file("good.rtt");
        m_bad = m_dir.file("bad.rtt");
        TraceWriter writer(m_good, 256);
        for (uint64_t i = 0; i < 2000; ++i) {
            const RayRecord r = test::ray_at(i);
            const HitRecord h = test::hit_at(i);
            writer.append(SectionKind::rays, &r, 1, sizeof r);
            writer.append(SectionKind::hits, &h, 1, sizeof h);
        }
        writer.append(SectionKind::work, std::vector<WorkRecord>(700, test::work_at(9)));
        writer.close();
        m_bytes = test::read_bytes(m_good);
        TraceReader reader(m_good);
        m_sections = reader.sections();
        m_header = tl::decode_header(m_bytes.data());
    }
    /// Writes `bytes` as the bad file and returns the error opening and fully reading it gives.
    std::string open_error(const std::vector<uint8_t>& bytes) {
        test::write_bytes(m_bad, bytes);
        return error_of([&] {
            TraceReader reader(m_bad);
            reader.verify_all();
        });
    }
    std::vector<uint8_t> flipped(uint64_t offset, int bit = 0) const {
        std::vector<uint8_t> b = m_bytes;
        b[offset] ^= uint8_t(1u << bit);
        return b;
    }

    test::ScratchDir m_dir;
    std::string m_good, m_bad;
    std::vector<uint8_t> m_bytes;
    std::vector<SectionInfo> m_sections;  // rays, hits, work
    tl::FileHeader m_header;
};

TEST_F(CorruptionTest, TruncationAnywhereIsRefused) {
    // Every cut inside the header and the section table, and a dense sample elsewhere.
    std::vector<uint64_t> cuts;
    for (uint64_t c = 0; c <= 64; ++c) cuts.push_back(c);
    for (uint64_t c = 65; c < m_bytes.size(); c += 37) cuts.push_back(c);
    for (uint64_t c = m_header.table_offset - 8; c < m_bytes.size(); ++c) cuts.push_back(c);
    for (const SectionInfo& s : m_sections) cuts.push_back(s.crc_offset + 2);  // inside a CRC table
    for (uint64_t cut : cuts) {
        const std::string msg = open_error(std::vector<uint8_t>(m_bytes.begin(), m_bytes.begin() + cut));
        ASSERT_TRUE(contains(msg, "truncated")) << "cut at " << cut << ": " << msg;
        ASSERT_EQ(msg.rfind(m_bad, 0), 0u) << msg;  // starts with the path
    }
    const std::string msg = open_error(std::vector<uint8_t>(m_bytes.begin(), m_bytes.begin() + 1000));
    const std::string expected =
        "truncated: header says " + std::to_string(m_bytes.size()) + " bytes, file has 1000";
    EXPECT_TRUE(contains(msg, expected)) << msg;
}

TEST_F(CorruptionTest, EveryHeaderBitFlipIsDetected) {
    for (uint64_t byte = 0; byte < 64; ++byte) {
        for (int bit = 0; bit < 8; bit += 3) {
            const std::string msg = open_error(flipped(byte, bit));
            const char* expected = byte < 8 ? "not an rtsim trace" : "header checksum mismatch";
            ASSERT_TRUE(contains(msg, expected)) << "byte " << byte << ": " << msg;
        }
    }
}

TEST_F(CorruptionTest, PayloadBitFlipNamesSectionAndChunk) {
    const char* names[] = {"RAYS", "HITS", "WORK"};
    for (size_t i = 0; i < m_sections.size(); ++i) {
        const SectionInfo& s = m_sections[i];
        for (uint64_t pos : {uint64_t(0), uint64_t(3 * 256 + 17), s.bytes / 2, s.bytes - 1}) {
            test::write_bytes(m_bad, flipped(s.offset + pos, 5));
            TraceReader reader(m_bad);  // payload damage is found when read, not at open
            const uint64_t chunk = pos / 256, end = std::min<uint64_t>((chunk + 1) * 256, s.bytes);
            const std::string expected = m_bad + ": checksum mismatch in section " + names[i] +
                                         " chunk " + std::to_string(chunk) + " (bytes " +
                                         std::to_string(chunk * 256) + ".." + std::to_string(end) + ")";
            EXPECT_EQ(error_of([&] { reader.verify_all(); }), expected);
            // A read touching only that chunk's record fails too; other sections still read.
            std::vector<uint8_t> one(s.record_bytes);
            const uint64_t record = pos / s.record_bytes;
            EXPECT_EQ(error_of([&] { reader.read(s.kind, record, 1, one.data()); }), expected);
            for (const SectionInfo& o : m_sections) {
                if (o.kind == s.kind) continue;
                std::vector<uint8_t> all(o.bytes);
                EXPECT_EQ(error_of([&] { reader.read(o.kind, 0, o.record_count, all.data()); }), "");
            }
        }
    }
}

TEST_F(CorruptionTest, ChunksOutsideTheDamageStillRead) {
    const SectionInfo& rays = m_sections[0];
    test::write_bytes(m_bad, flipped(rays.offset + 5 * 256 + 3));  // chunk 5 = bytes 1280..1536
    TraceReader reader(m_bad);
    std::vector<RayRecord> part(32);  // records 0..31 = bytes 0..1280: chunks 0..4
    EXPECT_EQ(error_of([&] { reader.read(SectionKind::rays, 0, 32, part.data()); }), "");
    const RayRecord expected = test::ray_at(31);
    EXPECT_EQ(std::memcmp(&part[31], &expected, sizeof(RayRecord)), 0);
    EXPECT_TRUE(contains(error_of([&] { reader.read(SectionKind::rays, 32, 1, part.data()); }), "chunk 5"));
}

TEST_F(CorruptionTest, CrcTableBitFlipNamesSectionAndChunk) {
    const SectionInfo& hits = m_sections[1];
    const std::string msg = open_error(flipped(hits.crc_offset + 4 * 7 + 2, 1));
    EXPECT_TRUE(contains(msg, "checksum mismatch in section HITS chunk 7")) << msg;
}

TEST_F(CorruptionTest, SectionTableBitFlipIsDetected) {
    for (uint64_t pos = m_header.table_offset; pos < m_bytes.size(); ++pos) {
        const std::string msg = open_error(flipped(pos, int(pos % 8)));
        ASSERT_TRUE(contains(msg, "section table checksum mismatch")) << "offset " << pos << ": " << msg;
    }
}

TEST_F(CorruptionTest, ForgedTableWithBadBoundsIsRefused) {
    // A table whose CRC is right but whose entry points past the payload area.
    std::vector<uint8_t> b = m_bytes;
    SectionInfo s = m_sections[1];
    s.offset = m_header.table_offset;  // 64-aligned, but the payload would overlap the table
    tl::encode_entry(s, &b[m_header.table_offset + tl::kEntryBytes]);
    const size_t n = m_header.table_bytes - 4;
    const uint32_t crc = tl::crc32_bytes(&b[m_header.table_offset], n);
    std::memcpy(&b[m_header.table_offset + n], &crc, 4);
    const std::string msg = open_error(b);
    EXPECT_TRUE(contains(msg, "section HITS payload out of bounds")) << msg;
}

TEST_F(CorruptionTest, WrongVersionAndForeignFilesAreRefused) {
    // A well-formed header (valid CRC) from a future version.
    std::vector<uint8_t> b = m_bytes;
    tl::FileHeader h = m_header;
    h.version = kTraceVersion + 1;
    tl::encode_header(h, b.data());
    const std::string reads = " is not supported by this build (reads versions " +
                              std::to_string(kTraceVersionOldest) + " to " + std::to_string(kTraceVersion) + ")";
    EXPECT_EQ(open_error(b), m_bad + ": trace version " + std::to_string(kTraceVersion + 1) + reads);
    // Versions before 3 (the BVH-only image) are refused the same way.
    h.version = kTraceVersionOldest - 1;
    tl::encode_header(h, b.data());
    EXPECT_EQ(open_error(b), m_bad + ": trace version " + std::to_string(kTraceVersionOldest - 1) + reads);
    // An older version's header over this version's records is refused by its WORK record
    // size (older versions are read with theirs: TraceRoundTrip.OlderWorkRecordsAreWidened...).
    h.version = 3;
    tl::encode_header(h, b.data());
    EXPECT_TRUE(contains(open_error(b), "section WORK has 40-byte records, this build expects 32")) << open_error(b);

    const std::string text = "This is a text file, long enough to fill a whole trace header, honestly.\n";
    EXPECT_EQ(open_error(std::vector<uint8_t>(text.begin(), text.end())),
              m_bad + ": not an rtsim trace (bad magic)");
    EXPECT_TRUE(contains(open_error({'R', 'T'}), "truncated"));

    b = m_bytes;
    b.push_back(0);
    EXPECT_TRUE(contains(open_error(b), "trailing data"));
    const std::string missing = m_dir.file("missing.rtt");
    EXPECT_TRUE(contains(error_of([&] { TraceReader r(missing); }), missing + ": cannot open trace"));
}

}  // namespace
}  // namespace rtsim
