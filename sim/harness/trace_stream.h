#pragma once
// Streams a trace into the model and the checker in chunks, so memory stays bounded however long
// the trace is (docs/architecture.md, rule 8).
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "rtl_model/dispatch/dispatch.h"
#include "traces/format/trace_reader.h"

namespace rtsim {

/// Reads rays [first, first + n) of the trace and appends them to `out` as RayJobs (ids are
/// their trace indices); `buffer` is scratch space reused between calls.
void read_ray_jobs(TraceReader& reader, uint64_t first, size_t n, std::vector<RayRecord>* buffer,
                   std::vector<RayJob>* out);

/// Rays of the trace, in order, as RayJobs.
class TraceRayStream : public RayStream {
public:
    explicit TraceRayStream(TraceReader& reader);
    size_t read_chunk(size_t max, std::vector<RayJob>* out) override;
    uint64_t total_rays() const override { return m_total; }

private:
    TraceReader& m_reader;
    uint64_t m_total;
    uint64_t m_next = 0;
    std::vector<RayRecord> m_buffer;
};

/// Evenly spread blocks of rays [first, first + total): the sample the verdict's analysis steps
/// (16 blocks, `sample` rays in all; the whole range when it is no larger).
class SampleStream : public RayStream {
public:
    SampleStream(TraceReader& reader, uint64_t first, uint64_t total, uint64_t sample);
    size_t read_chunk(size_t max, std::vector<RayJob>* out) override;
    uint64_t total_rays() const override { return m_total; }

private:
    TraceReader& m_reader;
    std::vector<std::pair<uint64_t, uint64_t>> m_blocks;  ///< first ray, rays left
    size_t m_next = 0;
    uint64_t m_total = 0;
    std::vector<RayRecord> m_buffer;
};

/// Where the hit checker looks up a ray's reference hit and work by its trace index.
class ReferenceSource {
public:
    virtual ~ReferenceSource() = default;
    virtual const HitRecord& hit(uint64_t id) = 0;
    virtual const WorkRecord& work(uint64_t id) = 0;
    /// Marks a ray as checked (its reference may be dropped).
    virtual void checked(uint64_t id) = 0;
};

/// Reference hits and work of the trace, looked up by ray index over a sliding window of chunks.
/// Rays complete roughly in order (within the rays in flight), so only a few chunks are resident.
class ReferenceWindow : public ReferenceSource {
public:
    ReferenceWindow(TraceReader& reader, uint64_t chunk_rays);
    const HitRecord& hit(uint64_t id) override { return chunk_for(id).hits[id % m_chunk]; }
    const WorkRecord& work(uint64_t id) override { return chunk_for(id).work[id % m_chunk]; }
    /// Marks a ray as checked; chunks whose rays are all checked are dropped.
    void checked(uint64_t id) override;
    size_t resident_chunks() const { return m_chunks.size(); }

private:
    struct Chunk {
        uint64_t index;
        std::vector<HitRecord> hits;
        std::vector<WorkRecord> work;
        uint64_t remaining;
        std::vector<bool> done;  ///< rays already checked: a second completion is a model bug
    };
    Chunk& chunk_for(uint64_t id);

    TraceReader& m_reader;
    uint64_t m_chunk, m_total;
    std::deque<Chunk> m_chunks;  ///< consecutive chunk indices, oldest first
    uint64_t m_loaded_end = 0;   ///< chunks [0, m_loaded_end) have been loaded (some retired)
};

}  // namespace rtsim
