#pragma once
// Trace reader: validates the header, version and section table on open (a truncated,
// corrupted or wrong-version file is refused with an Error naming the file and the problem),
// then streams any section in chunks, checking each chunk's CRC32 as it is read.
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "traces/format/trace_format.h"

namespace rtsim {

struct SectionInfo {
    SectionKind kind;
    uint32_t record_bytes = 0;
    uint64_t record_count = 0;
    uint64_t offset = 0;       ///< file offset of the payload (64-byte aligned)
    uint64_t bytes = 0;        ///< payload bytes = record_bytes * record_count
    uint32_t chunk_bytes = 0;  ///< payload bytes per CRC
    uint64_t crc_offset = 0;   ///< file offset of the uint32 CRC table (one per chunk)
};

class TraceReader {
public:
    explicit TraceReader(const std::string& path);
    ~TraceReader();
    TraceReader(const TraceReader&) = delete;
    TraceReader& operator=(const TraceReader&) = delete;

    const std::string& path() const { return m_path; }
    uint32_t version() const { return m_version; }
    const std::vector<SectionInfo>& sections() const { return m_sections; }
    bool has(SectionKind kind) const;
    const SectionInfo& section(SectionKind kind) const;  ///< throws Error if absent

    /// Reads records [first, first + count) of a section into out (record_bytes each; WORK
    /// records of older versions widened to this version's WorkRecord), verifying the CRC of
    /// every chunk it touches (each chunk is verified once per reader).
    void read(SectionKind kind, uint64_t first, uint64_t count, void* out);
    template <class T>
    std::vector<T> read_all(SectionKind kind) {
        const SectionInfo& s = section(kind);
        std::vector<T> out(s.record_count);
        read(kind, 0, s.record_count, out.data());
        return out;
    }
    /// Verifies every chunk of every section; throws Error naming the first bad chunk.
    void verify_all();
    /// Verifies every chunk of one section (once per reader); throws Error naming the bad chunk.
    void verify_section(SectionKind kind);

private:
    /// read() of the stored bytes, without widening older records.
    void read_raw(SectionKind kind, uint64_t first, uint64_t count, void* out);
    void verify_chunk(const SectionInfo& s, size_t section_index, uint64_t chunk);

    std::string m_path;
    std::FILE* m_file = nullptr;
    uint64_t m_file_bytes = 0;
    uint32_t m_version = 0;
    std::vector<SectionInfo> m_sections;
    std::vector<std::vector<bool>> m_verified;  ///< per section, per chunk
};

}  // namespace rtsim
