// Little-endian encoding of the trace header and section-table entries.
#include "traces/format/trace_layout.h"

#include <cstdio>
#include <cstring>

#include <zlib.h>

namespace rtsim::trace_layout {
namespace {

void put_u32(uint8_t* p, uint32_t v) {
    for (int i = 0; i < 4; ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}
void put_u64(uint8_t* p, uint64_t v) {
    for (int i = 0; i < 8; ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}
uint32_t get_u32(const uint8_t* p) {
    uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= static_cast<uint32_t>(p[i]) << (8 * i);
    return v;
}
uint64_t get_u64(const uint8_t* p) {
    uint64_t v = 0;
    for (int i = 0; i < 8; ++i) v |= static_cast<uint64_t>(p[i]) << (8 * i);
    return v;
}

}  // namespace

uint32_t crc32_bytes(const void* data, size_t bytes, uint32_t crc) {
    // zlib takes uInt lengths: feed huge ranges in 1 GiB slices.
    const auto* p = static_cast<const Bytef*>(data);
    uLong c = crc;
    while (bytes > 0) {
        const size_t n = bytes < (1u << 30) ? bytes : (1u << 30);
        c = ::crc32(c, p, static_cast<uInt>(n));
        p += n;
        bytes -= n;
    }
    return static_cast<uint32_t>(c);
}

void encode_header(const FileHeader& h, uint8_t* out) {
    std::memset(out, 0, kHeaderBytes);
    std::memcpy(out, kTraceMagic, 8);
    put_u32(out + 8, h.version);
    put_u32(out + 12, h.header_bytes);
    put_u32(out + 16, h.section_count);
    put_u32(out + 20, h.flags);
    put_u64(out + 24, h.table_offset);
    put_u64(out + 32, h.table_bytes);
    put_u64(out + 40, h.file_bytes);
    put_u32(out + 60, crc32_bytes(out, 60));  // bytes 48..59 stay reserved (zero)
}

FileHeader decode_header(const uint8_t* in) {
    FileHeader h;
    h.version = get_u32(in + 8);
    h.header_bytes = get_u32(in + 12);
    h.section_count = get_u32(in + 16);
    h.flags = get_u32(in + 20);
    h.table_offset = get_u64(in + 24);
    h.table_bytes = get_u64(in + 32);
    h.file_bytes = get_u64(in + 40);
    return h;
}

bool header_crc_ok(const uint8_t* in) { return get_u32(in + 60) == crc32_bytes(in, 60); }

void encode_entry(const SectionInfo& s, uint8_t* out) {
    std::memset(out, 0, kEntryBytes);
    put_u32(out + 0, static_cast<uint32_t>(s.kind));
    put_u32(out + 4, s.record_bytes);
    put_u64(out + 8, s.record_count);
    put_u64(out + 16, s.offset);
    put_u64(out + 24, s.bytes);
    put_u32(out + 32, s.chunk_bytes);
    put_u64(out + 40, s.crc_offset);  // 36..39 and 48..63 reserved (zero)
}

SectionInfo decode_entry(const uint8_t* in) {
    SectionInfo s;
    s.kind = static_cast<SectionKind>(get_u32(in + 0));
    s.record_bytes = get_u32(in + 4);
    s.record_count = get_u64(in + 8);
    s.offset = get_u64(in + 16);
    s.bytes = get_u64(in + 24);
    s.chunk_bytes = get_u32(in + 32);
    s.crc_offset = get_u64(in + 40);
    return s;
}

std::string kind_label(SectionKind kind) {
    if (section_record_bytes(kind) != 0) return section_name(kind);
    // Unknown kind: its four characters if printable, else hex.
    const auto v = static_cast<uint32_t>(kind);
    std::string text;
    for (int i = 0; i < 4; ++i) {
        const char c = static_cast<char>((v >> (8 * i)) & 0xFF);
        if (c < 0x20 || c > 0x7E) {
            char hex[16];
            std::snprintf(hex, sizeof hex, "0x%08X", v);
            return hex;
        }
        text += c;
    }
    return text;
}

}  // namespace rtsim::trace_layout
