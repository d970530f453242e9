#pragma once
// On-disk encoding of the trace file's header and section-table entries (internal to the
// format library; docs/trace_format.md is the byte-by-byte reference). Fields are encoded
// explicitly little-endian; the records themselves are stored as-is, hence the host check.
#include <cstddef>
#include <cstdint>
#include <string>

#include "traces/format/trace_format.h"
#include "traces/format/trace_reader.h"

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "trace records are stored in host order, which must be little-endian");

namespace rtsim::trace_layout {

constexpr uint32_t kHeaderBytes = 64;  ///< fixed header at offset 0
constexpr uint32_t kEntryBytes = 64;   ///< one section-table entry
constexpr uint64_t kAlign = 64;        ///< payloads, CRC tables and the section table start here

/// The header's fields after the magic (the magic and the CRC are handled by encode/decode).
struct FileHeader {
    uint32_t version = kTraceVersion;
    uint32_t header_bytes = kHeaderBytes;
    uint32_t section_count = 0;
    uint32_t flags = 0;
    uint64_t table_offset = 0;  ///< file offset of the section table
    uint64_t table_bytes = 0;   ///< section_count * kEntryBytes + 4 (the table's CRC32)
    uint64_t file_bytes = 0;    ///< total file size
};

inline uint64_t align_up(uint64_t x) { return (x + kAlign - 1) / kAlign * kAlign; }
inline uint64_t chunk_count(uint64_t bytes, uint32_t chunk_bytes) {
    return chunk_bytes == 0 ? 0 : (bytes + chunk_bytes - 1) / chunk_bytes;
}
inline uint64_t table_bytes_for(uint64_t section_count) {
    return section_count * kEntryBytes + 4;
}

/// zlib CRC32 of a byte range, continuing from `crc` (0 to start).
uint32_t crc32_bytes(const void* data, size_t bytes, uint32_t crc = 0);

/// Writes magic, fields and the header CRC (over bytes 0..59) into out[64].
void encode_header(const FileHeader& h, uint8_t* out);
/// Reads the fields (no validation); header_crc_ok tells whether bytes 60..63 match.
FileHeader decode_header(const uint8_t* in);
bool header_crc_ok(const uint8_t* in);

void encode_entry(const SectionInfo& s, uint8_t* out);
SectionInfo decode_entry(const uint8_t* in);

/// "RAYS", ... for known kinds; the fourcc text (or hex) for others. For messages and spools.
std::string kind_label(SectionKind kind);

}  // namespace rtsim::trace_layout
