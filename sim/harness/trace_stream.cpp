#include "sim/harness/trace_stream.h"

#include <algorithm>

#include "traces/common/error.h"
#include "traces/format/trace_checks.h"

namespace rtsim {

TraceRayStream::TraceRayStream(TraceReader& reader)
    : m_reader(reader), m_total(reader.section(SectionKind::rays).record_count) {}

void read_ray_jobs(TraceReader& reader, uint64_t first, size_t n, std::vector<RayRecord>* buffer,
                   std::vector<RayJob>* out) {
    buffer->resize(n);
    reader.read(SectionKind::rays, first, n, buffer->data());
    for (size_t i = 0; i < n; ++i) {
        RayJob job;
        job.id = first + i;
        job.ray = ray_from_record((*buffer)[i]);
        job.any_hit = (*buffer)[i].flags & kRayFlagAnyHit;
        const uint8_t kind = (*buffer)[i].kind;
        job.kind = kind < kRayKindCount ? RayKind(kind) : RayKind::primary;
        out->push_back(job);
    }
}

SampleStream::SampleStream(TraceReader& reader, uint64_t first, uint64_t total, uint64_t sample) : m_reader(reader) {
    const uint64_t blocks = total <= sample ? 1 : 16, block = total <= sample ? total : sample / blocks;
    for (uint64_t b = 0; b < blocks; ++b) m_blocks.push_back({first + b * (total / blocks), block});
    m_total = blocks * block;
}

size_t SampleStream::read_chunk(size_t max, std::vector<RayJob>* out) {
    if (m_next == m_blocks.size()) return 0;
    auto& [first, left] = m_blocks[m_next];
    const size_t n = size_t(std::min<uint64_t>(max, left));
    read_ray_jobs(m_reader, first, n, &m_buffer, out);
    first += n;
    left -= n;
    if (left == 0) ++m_next;
    return n;
}

size_t TraceRayStream::read_chunk(size_t max, std::vector<RayJob>* out) {
    size_t n = size_t(std::min<uint64_t>(max, m_total - m_next));
    if (n == 0) return 0;
    read_ray_jobs(m_reader, m_next, n, &m_buffer, out);
    m_next += n;
    return n;
}

ReferenceWindow::ReferenceWindow(TraceReader& reader, uint64_t chunk_rays)
    : m_reader(reader), m_chunk(chunk_rays), m_total(reader.section(SectionKind::hits).record_count) {
    check_ray_sections(reader);
}

ReferenceWindow::Chunk& ReferenceWindow::chunk_for(uint64_t id) {
    // Called for every ray: messages are built only when a check fails.
    const uint64_t index = id / m_chunk;
    if (id >= m_total)
        throw Error("ray " + std::to_string(id) + " is beyond the trace (" + std::to_string(m_total) + " rays)");
    if (!m_chunks.empty() && index >= m_chunks.front().index && index < m_chunks.front().index + m_chunks.size())
        return m_chunks[index - m_chunks.front().index];
    if (index < m_loaded_end)
        throw Error("ray " + std::to_string(id) +
                    " finished after all rays of its chunk were checked (a ray was duplicated in the model)");
    // Load consecutive chunks up to the one needed. Always from the first chunk never loaded, even
    // when every resident chunk has retired: rays of the chunks in between may still be in flight.
    uint64_t next = m_loaded_end;
    while (next <= index) {
        uint64_t first = next * m_chunk, n = std::min(m_chunk, m_total - first);
        Chunk c{next, std::vector<HitRecord>(n), std::vector<WorkRecord>(n), n, std::vector<bool>(n, false)};
        m_reader.read(SectionKind::hits, first, n, c.hits.data());
        m_reader.read(SectionKind::work, first, n, c.work.data());
        m_chunks.push_back(std::move(c));
        ++next;
    }
    m_loaded_end = next;
    return m_chunks.back();
}

void ReferenceWindow::checked(uint64_t id) {
    Chunk& c = chunk_for(id);
    if (c.done[id % m_chunk])
        throw Error("ray " + std::to_string(id) + " finished twice (a ray was duplicated in the model)");
    c.done[id % m_chunk] = true;
    --c.remaining;
    while (!m_chunks.empty() && m_chunks.front().remaining == 0) m_chunks.pop_front();
}

}  // namespace rtsim
