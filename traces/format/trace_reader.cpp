// Validating trace reader: everything that can be checked without reading the payloads is
// checked on open (magic, size, header CRC, version, section table CRC and bounds); payload
// chunks are checked against their CRC32 the first time a read touches them.
#include "traces/format/trace_reader.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <memory>

#include "traces/common/error.h"
#include "traces/common/files.h"
#include "traces/format/trace_layout.h"

namespace rtsim {
namespace tl = trace_layout;

namespace {

constexpr size_t kVerifyBuffer = 64u << 10;  // verify_chunk streams a chunk in pieces this big

std::string num(uint64_t v) { return std::to_string(v); }

/// The error for a chunk whose CRC does not match; bytes are relative to the section payload.
Error chunk_error(const std::string& path, const SectionInfo& s, uint64_t chunk) {
    const uint64_t begin = chunk * s.chunk_bytes, end = std::min(begin + s.chunk_bytes, s.bytes);
    return Error(path + ": checksum mismatch in section " + trace_layout::kind_label(s.kind) + " chunk " +
                 num(chunk) + " (bytes " + num(begin) + ".." + num(end) + ")");
}

/// Reads exactly n bytes at offset; a short read means the file shrank after open.
void read_at(std::FILE* f, const std::string& path, uint64_t offset, uint64_t n, void* out) {
    if (n == 0) return;
    if (fseeko(f, static_cast<off_t>(offset), SEEK_SET) != 0 ||
        std::fread(out, 1, static_cast<size_t>(n), f) != n)
        throw Error(path + ": truncated: cannot read " + num(n) + " bytes at offset " + num(offset) +
                    " (file changed since it was opened?)");
}

/// Header checks, in the order that gives the most useful message first.
tl::FileHeader check_header(std::FILE* f, const std::string& path, uint64_t file_bytes) {
    uint8_t head[tl::kHeaderBytes] = {};
    const uint64_t got = std::min<uint64_t>(file_bytes, tl::kHeaderBytes);
    read_at(f, path, 0, got, head);
    require(std::memcmp(head, kTraceMagic, std::min<uint64_t>(got, 8)) == 0,
            path + ": not an rtsim trace (bad magic)");
    require(file_bytes >= tl::kHeaderBytes,
            path + ": truncated: file has " + num(file_bytes) + " bytes, less than the " +
                num(tl::kHeaderBytes) + "-byte header");
    // The header CRC (bytes 60..63 over 0..59) is the same in every version, so it comes first.
    require(tl::header_crc_ok(head), path + ": header checksum mismatch (header is corrupt)");
    const tl::FileHeader h = tl::decode_header(head);
    // Version 3 is version 4 without frames (no FRMS section), version 4 is version 5 without the
    // shading sections: all three are read (a reader asks has() before it reads an optional section).
    require(h.version >= kTraceVersionOldest && h.version <= kTraceVersion,
            path + ": trace version " + num(h.version) + " is not supported by this build (reads versions " +
                num(kTraceVersionOldest) + " to " + num(kTraceVersion) + ")");
    require(h.header_bytes == tl::kHeaderBytes,
            path + ": header_bytes is " + num(h.header_bytes) + ", expected " + num(tl::kHeaderBytes));
    require(file_bytes >= h.file_bytes, path + ": truncated: header says " + num(h.file_bytes) +
                                            " bytes, file has " + num(file_bytes));
    require(file_bytes == h.file_bytes, path + ": header says " + num(h.file_bytes) + " bytes, file has " +
                                            num(file_bytes) + " (trailing data)");
    require(h.table_bytes == tl::table_bytes_for(h.section_count) && h.table_bytes <= h.file_bytes &&
                h.table_offset == h.file_bytes - h.table_bytes && h.table_offset >= tl::kHeaderBytes,
            path + ": section table out of bounds (" + num(h.section_count) + " sections, offset " +
                num(h.table_offset) + ", " + num(h.table_bytes) + " bytes, file " + num(h.file_bytes) +
                " bytes)");
    return h;
}

/// Bounds and consistency of one section-table entry; payload and CRC table lie before the table.
void check_entry(const std::string& path, const SectionInfo& s, uint64_t table_offset, uint32_t version) {
    const std::string where = path + ": section table: section " + tl::kind_label(s.kind) + " ";
    const uint32_t expected =
        s.kind == SectionKind::work && version < 6 ? kWorkRecordBytesV5 : section_record_bytes(s.kind);
    require(s.record_bytes > 0, where + "has 0-byte records");
    require(expected == 0 || expected == s.record_bytes,
            where + "has " + num(s.record_bytes) + "-byte records, this build expects " + num(expected));
    require(s.record_count <= UINT64_MAX / s.record_bytes && s.bytes == s.record_count * s.record_bytes,
            where + "is " + num(s.bytes) + " bytes, not " + num(s.record_count) + " records of " +
                num(s.record_bytes) + " bytes");
    require(s.offset >= tl::kHeaderBytes && s.offset % tl::kAlign == 0 && s.offset <= table_offset &&
                s.bytes <= table_offset - s.offset,
            where + "payload out of bounds (offset " + num(s.offset) + ", " + num(s.bytes) + " bytes)");
    require(s.chunk_bytes > 0, where + "has chunk_bytes 0");
    const uint64_t chunks = tl::chunk_count(s.bytes, s.chunk_bytes);
    require(s.crc_offset >= tl::kHeaderBytes && s.crc_offset <= table_offset &&
                chunks <= (table_offset - s.crc_offset) / 4,
            where + "CRC table out of bounds (offset " + num(s.crc_offset) + ", " + num(chunks) + " chunks)");
}

}  // namespace

TraceReader::TraceReader(const std::string& path) : m_path(path) {
    require_regular_file(path, "trace file (trace.rtt)");  // a FIFO would block the open
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"), &std::fclose);
    require(file != nullptr, path + ": cannot open trace: " + std::strerror(errno));
    std::FILE* f = file.get();
    std::setvbuf(f, nullptr, _IONBF, 0);  // reads are large or few; no double copy
    require(fseeko(f, 0, SEEK_END) == 0, path + ": cannot seek: " + std::strerror(errno));
    m_file_bytes = static_cast<uint64_t>(ftello(f));

    const tl::FileHeader h = check_header(f, path, m_file_bytes);
    m_version = h.version;
    // Section table: CRC over the entries, then each entry's bounds.
    std::vector<uint8_t> table(h.table_bytes);
    read_at(f, path, h.table_offset, table.size(), table.data());
    const size_t n = table.size() - 4;
    const uint32_t stored = table[n] | table[n + 1] << 8 | table[n + 2] << 16 | uint32_t(table[n + 3]) << 24;
    require(stored == tl::crc32_bytes(table.data(), n), path + ": section table checksum mismatch");
    for (uint32_t i = 0; i < h.section_count; ++i) {
        const SectionInfo s = tl::decode_entry(&table[size_t(i) * tl::kEntryBytes]);
        check_entry(path, s, h.table_offset, h.version);
        for (const SectionInfo& other : m_sections)
            require(other.kind != s.kind,
                    path + ": section table: section " + tl::kind_label(s.kind) + " appears twice");
        m_sections.push_back(s);
        m_verified.emplace_back(tl::chunk_count(s.bytes, s.chunk_bytes), false);
    }
    m_file = file.release();
}

TraceReader::~TraceReader() {
    if (m_file) std::fclose(m_file);
}

bool TraceReader::has(SectionKind kind) const {
    for (const SectionInfo& s : m_sections)
        if (s.kind == kind) return true;
    return false;
}

const SectionInfo& TraceReader::section(SectionKind kind) const {
    for (const SectionInfo& s : m_sections)
        if (s.kind == kind) return s;
    std::string present;
    for (const SectionInfo& s : m_sections) present += (present.empty() ? "" : ", ") + tl::kind_label(s.kind);
    throw Error(m_path + ": no section " + tl::kind_label(kind) + " in this trace (has: " +
                (present.empty() ? "none" : present) + ")");
}

void TraceReader::read(SectionKind kind, uint64_t first, uint64_t count, void* out) {
    const SectionInfo& s = section(kind);
    if (kind != SectionKind::work || s.record_bytes == sizeof(WorkRecord)) return read_raw(kind, first, count, out);
    // An older version's WORK records (fewer fields): read as stored, widened with zeros (the
    // counters it predates count nothing there).
    std::vector<uint8_t> stored(size_t(count * s.record_bytes));
    read_raw(kind, first, count, stored.data());
    auto* dst = static_cast<WorkRecord*>(out);
    for (uint64_t i = 0; i < count; ++i) {
        dst[i] = WorkRecord{};
        std::memcpy(&dst[i], stored.data() + i * s.record_bytes, s.record_bytes);
    }
}

void TraceReader::read_raw(SectionKind kind, uint64_t first, uint64_t count, void* out) {
    const SectionInfo& s = section(kind);
    const size_t index = static_cast<size_t>(&s - m_sections.data());
    require(first <= s.record_count && count <= s.record_count - first,
            m_path + ": section " + tl::kind_label(kind) + ": records [" + num(first) + ", " +
                num(first + count) + ") out of range (section has " + num(s.record_count) + ")");
    if (count == 0) return;
    const uint64_t begin = first * s.record_bytes, end = begin + count * s.record_bytes;
    auto* dst = static_cast<uint8_t*>(out);
    // Chunk by chunk: a chunk wholly inside the request is read into `out` and checked there;
    // a partly covered one is verified separately first (once), then its overlap is read.
    for (uint64_t c = begin / s.chunk_bytes; c * s.chunk_bytes < end; ++c) {
        const uint64_t cb = c * s.chunk_bytes, ce = std::min(cb + s.chunk_bytes, s.bytes);
        const uint64_t ob = std::max(cb, begin), oe = std::min(ce, end);
        const bool whole = cb >= begin && ce <= end;
        if (!m_verified[index][c] && !whole) verify_chunk(s, index, c);
        read_at(m_file, m_path, s.offset + ob, oe - ob, dst + (ob - begin));
        if (m_verified[index][c]) continue;
        uint32_t stored_le = 0;
        read_at(m_file, m_path, s.crc_offset + 4 * c, 4, &stored_le);
        if (tl::crc32_bytes(dst + (ob - begin), static_cast<size_t>(oe - ob)) != stored_le)
            throw chunk_error(m_path, s, c);
        m_verified[index][c] = true;
    }
}

void TraceReader::verify_chunk(const SectionInfo& s, size_t section_index, uint64_t chunk) {
    // Stream the chunk through a small buffer, so verification needs no chunk-sized memory.
    const uint64_t cb = chunk * s.chunk_bytes, ce = std::min(cb + s.chunk_bytes, s.bytes);
    std::vector<uint8_t> buffer(static_cast<size_t>(std::min<uint64_t>(ce - cb, kVerifyBuffer)));
    uint32_t crc = 0;
    for (uint64_t pos = cb; pos < ce;) {
        const uint64_t n = std::min<uint64_t>(ce - pos, buffer.size());
        read_at(m_file, m_path, s.offset + pos, n, buffer.data());
        crc = tl::crc32_bytes(buffer.data(), static_cast<size_t>(n), crc);
        pos += n;
    }
    uint32_t stored_le = 0;
    read_at(m_file, m_path, s.crc_offset + 4 * chunk, 4, &stored_le);
    if (crc != stored_le) throw chunk_error(m_path, s, chunk);
    m_verified[section_index][chunk] = true;
}

void TraceReader::verify_all() {
    for (const SectionInfo& s : m_sections) verify_section(s.kind);
}

void TraceReader::verify_section(SectionKind kind) {
    const SectionInfo& s = section(kind);
    const size_t i = static_cast<size_t>(&s - m_sections.data());
    for (uint64_t c = 0; c < m_verified[i].size(); ++c)
        if (!m_verified[i][c]) verify_chunk(s, i, c);
}

}  // namespace rtsim
