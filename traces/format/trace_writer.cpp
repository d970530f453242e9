// Streaming trace writer: one spool file per section (OUT.partial.<KIND>), per-chunk CRC32s
// computed as records arrive, and a close() that concatenates everything into OUT.partial,
// fsyncs it and renames it over OUT. Memory: one spool buffer per section + 4 B per chunk.
#include "traces/format/trace_writer.h"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fcntl.h>
#include <unistd.h>

#include "traces/common/error.h"
#include "traces/format/trace_layout.h"

namespace rtsim {
namespace tl = trace_layout;

namespace {

constexpr size_t kSpoolBuffer = 256u << 10;  // stdio buffer per section spool
constexpr size_t kCopyBuffer = 1u << 20;     // close(): spool-to-output copy buffer

std::string errno_text() { return std::strerror(errno); }

/// fsync of the folder holding `path`, so a completed rename survives a crash (best effort).
void sync_directory(const std::string& path) {
    std::string dir = std::filesystem::path(path).parent_path().string();
    if (dir.empty()) dir = ".";
    const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY);
    if (fd < 0) return;
    ::fsync(fd);
    ::close(fd);
}

/// One section being spooled: its temporary file and the CRCs of its completed chunks.
struct Spool {
    SectionKind kind{};
    uint32_t record_bytes = 0;
    uint64_t bytes = 0;
    std::string path;
    std::FILE* file = nullptr;
    std::unique_ptr<char[]> buffer;
    std::vector<uint32_t> crcs;  ///< one per completed chunk
    uint32_t chunk_crc = 0;      ///< running CRC of the current, incomplete chunk
    uint64_t chunk_fill = 0;     ///< bytes in the current chunk
};

/// Sequential output with a position, so padding and offsets can be checked as written.
struct OutFile {
    std::string path;
    std::FILE* file = nullptr;
    uint64_t pos = 0;
    void write(const void* data, size_t n) {
        if (n != 0 && std::fwrite(data, 1, n, file) != n)
            throw Error(path + ": write failed: " + errno_text());
        pos += n;
    }
    void pad_to(uint64_t offset) {
        static const char zeros[tl::kAlign] = {};
        while (pos < offset) write(zeros, static_cast<size_t>(std::min<uint64_t>(offset - pos, tl::kAlign)));
    }
};

}  // namespace

struct TraceWriter::Impl {
    std::string path;
    uint32_t chunk_bytes = 0;
    std::vector<Spool> spools;  ///< in order of first append (the order in the file)
    bool closed = false;

    Spool& spool_for(SectionKind kind, uint32_t record_bytes);
    void feed_crc(Spool& s, const uint8_t* data, uint64_t n) const;
    void write_file(const std::string& partial);
    void discard();
};

Spool& TraceWriter::Impl::spool_for(SectionKind kind, uint32_t record_bytes) {
    const std::string label = tl::kind_label(kind);
    for (Spool& s : spools) {
        if (s.kind != kind) continue;
        require(s.record_bytes == record_bytes,
                path + ": section " + label + " has " + std::to_string(s.record_bytes) +
                    "-byte records, cannot append " + std::to_string(record_bytes) + "-byte records");
        return s;
    }
    // First use: check the record size and open the section's spool file.
    const uint32_t expected = section_record_bytes(kind);
    require(record_bytes > 0, path + ": section " + label + ": record size must be positive");
    require(expected == 0 || expected == record_bytes,
            path + ": section " + label + " needs " + std::to_string(expected) +
                "-byte records, got " + std::to_string(record_bytes));
    Spool s;
    s.kind = kind;
    s.record_bytes = record_bytes;
    s.path = path + ".partial." + label;
    s.file = std::fopen(s.path.c_str(), "w+b");
    require(s.file != nullptr, s.path + ": cannot create spool file: " + errno_text());
    s.buffer.reset(new char[kSpoolBuffer]);
    std::setvbuf(s.file, s.buffer.get(), _IOFBF, kSpoolBuffer);
    spools.push_back(std::move(s));
    return spools.back();
}

void TraceWriter::Impl::feed_crc(Spool& s, const uint8_t* data, uint64_t n) const {
    // Split the bytes at chunk boundaries; each completed chunk's CRC is kept.
    while (n > 0) {
        const uint64_t take = std::min<uint64_t>(n, chunk_bytes - s.chunk_fill);
        s.chunk_crc = tl::crc32_bytes(data, static_cast<size_t>(take), s.chunk_crc);
        s.chunk_fill += take;
        data += take;
        n -= take;
        if (s.chunk_fill == chunk_bytes) {
            s.crcs.push_back(s.chunk_crc);
            s.chunk_crc = 0;
            s.chunk_fill = 0;
        }
    }
}

void TraceWriter::Impl::write_file(const std::string& partial) {
    // Layout: header, 64-aligned payloads, 64-aligned CRC tables, 64-aligned section table.
    std::vector<SectionInfo> infos;
    uint64_t pos = tl::kHeaderBytes;
    for (Spool& s : spools) {
        if (s.chunk_fill > 0) s.crcs.push_back(s.chunk_crc);
        s.chunk_fill = 0;
        SectionInfo info{s.kind, s.record_bytes, s.bytes / s.record_bytes};
        info.offset = tl::align_up(pos);
        info.bytes = s.bytes;
        info.chunk_bytes = chunk_bytes;
        pos = info.offset + info.bytes;
        infos.push_back(info);
    }
    for (size_t i = 0; i < spools.size(); ++i) {
        infos[i].crc_offset = tl::align_up(pos);
        pos = infos[i].crc_offset + 4 * spools[i].crcs.size();
    }
    tl::FileHeader header;
    header.section_count = static_cast<uint32_t>(spools.size());
    header.table_offset = tl::align_up(pos);
    header.table_bytes = tl::table_bytes_for(spools.size());
    header.file_bytes = header.table_offset + header.table_bytes;

    OutFile out{partial, std::fopen(partial.c_str(), "wb")};
    require(out.file != nullptr, partial + ": cannot create: " + errno_text());
    try {
        uint8_t head[tl::kHeaderBytes];
        tl::encode_header(header, head);
        out.write(head, sizeof head);
        // Payloads: copy each spool in order.
        std::vector<char> buffer(kCopyBuffer);
        for (size_t i = 0; i < spools.size(); ++i) {
            out.pad_to(infos[i].offset);
            std::FILE* in = spools[i].file;
            require(std::fflush(in) == 0 && std::fseek(in, 0, SEEK_SET) == 0,
                    spools[i].path + ": cannot rewind spool: " + errno_text());
            uint64_t left = spools[i].bytes;
            while (left > 0) {
                const size_t n = static_cast<size_t>(std::min<uint64_t>(left, buffer.size()));
                require(std::fread(buffer.data(), 1, n, in) == n,
                        spools[i].path + ": spool file shorter than written");
                out.write(buffer.data(), n);
                left -= n;
            }
        }
        // CRC tables, then the section table and its own CRC.
        for (size_t i = 0; i < spools.size(); ++i) {
            out.pad_to(infos[i].crc_offset);
            for (uint32_t crc : spools[i].crcs) {
                uint8_t le[4] = {uint8_t(crc), uint8_t(crc >> 8), uint8_t(crc >> 16), uint8_t(crc >> 24)};
                out.write(le, 4);
            }
        }
        out.pad_to(header.table_offset);
        std::vector<uint8_t> table(header.table_bytes, 0);
        for (size_t i = 0; i < infos.size(); ++i) tl::encode_entry(infos[i], &table[i * tl::kEntryBytes]);
        const uint32_t table_crc = tl::crc32_bytes(table.data(), table.size() - 4);
        for (int b = 0; b < 4; ++b) table[table.size() - 4 + b] = uint8_t(table_crc >> (8 * b));
        out.write(table.data(), table.size());
        require(out.pos == header.file_bytes, partial + ": internal error: size mismatch");
        // Durable before the rename makes it visible.
        require(std::fflush(out.file) == 0 && ::fsync(fileno(out.file)) == 0,
                partial + ": cannot flush: " + errno_text());
    } catch (...) {
        std::fclose(out.file);
        throw;
    }
    require(std::fclose(out.file) == 0, partial + ": cannot close: " + errno_text());
}

void TraceWriter::Impl::discard() {
    for (Spool& s : spools) {
        if (s.file) std::fclose(s.file);
        s.file = nullptr;
        std::remove(s.path.c_str());
    }
    spools.clear();
    std::remove((path + ".partial").c_str());
}

TraceWriter::TraceWriter(const std::string& path, uint32_t chunk_bytes) : m_impl(new Impl) {
    require(!path.empty(), "trace writer: empty output path");
    require(chunk_bytes > 0, path + ": chunk_bytes must be positive");
    m_impl->path = path;
    m_impl->chunk_bytes = chunk_bytes;
}

TraceWriter::~TraceWriter() {
    if (!m_impl->closed) m_impl->discard();
}

void TraceWriter::append(SectionKind kind, const void* records, uint64_t count, uint32_t record_bytes) {
    require(!m_impl->closed, m_impl->path + ": append after close()");
    Spool& s = m_impl->spool_for(kind, record_bytes);
    require(count <= UINT64_MAX / record_bytes - s.bytes / record_bytes,
            m_impl->path + ": section " + tl::kind_label(kind) + " too large");
    const uint64_t n = count * record_bytes;
    if (n == 0) return;
    if (std::fwrite(records, 1, static_cast<size_t>(n), s.file) != n)
        throw Error(s.path + ": write failed: " + errno_text());
    m_impl->feed_crc(s, static_cast<const uint8_t*>(records), n);
    s.bytes += n;
}

void TraceWriter::close() {
    Impl& im = *m_impl;
    require(!im.closed, im.path + ": close() called twice");
    const std::string partial = im.path + ".partial";
    try {
        im.write_file(partial);
        // Spools are no longer needed; the rename is the commit point.
        for (Spool& s : im.spools) {
            std::fclose(s.file);
            s.file = nullptr;
            std::remove(s.path.c_str());
        }
        if (std::rename(partial.c_str(), im.path.c_str()) != 0)
            throw Error(im.path + ": cannot rename " + partial + " into place: " + errno_text());
    } catch (...) {
        im.discard();
        im.closed = true;
        throw;
    }
    im.spools.clear();
    im.closed = true;
    sync_directory(im.path);
}

}  // namespace rtsim
