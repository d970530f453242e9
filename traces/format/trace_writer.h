#pragma once
// Streaming trace writer. Sections are appended record by record (in any interleaving); each is
// spooled to its own temporary file and concatenated into the final file by close(), which
// writes the CRC tables and the section table last. Until close() succeeds the output path is
// not touched (the file is written as OUT.partial and renamed), so nothing already there is lost.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "traces/format/trace_format.h"

namespace rtsim {

class TraceWriter {
public:
    /// chunk_bytes: payload bytes covered by one CRC32 (1 MiB default).
    explicit TraceWriter(const std::string& path, uint32_t chunk_bytes = 1u << 20);
    ~TraceWriter();  // discards the partial file if close() was not called
    TraceWriter(const TraceWriter&) = delete;
    TraceWriter& operator=(const TraceWriter&) = delete;

    /// Appends `count` records of `record_bytes` each to a section (created on first use; the
    /// record size of a section must not change).
    void append(SectionKind kind, const void* records, uint64_t count, uint32_t record_bytes);
    template <class T>
    void append(SectionKind kind, const std::vector<T>& records) {
        append(kind, records.data(), records.size(), sizeof(T));
    }
    void close();

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

}  // namespace rtsim
