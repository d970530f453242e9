#include "sim/harness/alternative_trace.h"

#include <cstring>
#include <filesystem>
#include <vector>

#include "sim/analytic/analysis_cache.h"
#include "sim/harness/trace_stream.h"
#include "sim/resolve/resolve.h"
#include "traces/accel/accel_io.h"
#include "traces/common/error.h"

namespace rtsim {

namespace fs = std::filesystem;

namespace {

/// What an opened alternative owns: its file, structure and memory map.
struct OpenedAlternative : AlternativeTrace {
    std::unique_ptr<TraceReader> reader;
    std::unique_ptr<Accel> owned_accel;
    std::unique_ptr<MemoryMap> owned_map;
};

/// True when both traces hold the same rays in the same order (the same workload: structures
/// differ in work, never in hits, so the tracer generates the same secondary rays).
bool same_rays(TraceReader& a, TraceReader& b) {
    const uint64_t n = a.section(SectionKind::rays).record_count;
    if (b.section(SectionKind::rays).record_count != n) return false;
    constexpr uint64_t kChunk = 1 << 16;
    std::vector<RayRecord> x(kChunk), y(kChunk);
    for (uint64_t first = 0; first < n; first += kChunk) {
        const uint64_t count = std::min(kChunk, n - first);
        a.read(SectionKind::rays, first, count, x.data());
        b.read(SectionKind::rays, first, count, y.data());
        if (std::memcmp(x.data(), y.data(), count * sizeof(RayRecord)) != 0) return false;
    }
    return true;
}

}  // namespace

AlternativeFactory alternative_traces(const std::string& rtt, const SimConfig& config, uint64_t rays) {
    const fs::path dir = fs::path(rtt).parent_path();
    return [dir, rtt, config, rays](const std::string& key, const std::string& value,
                                    std::string* why) -> std::unique_ptr<AlternativeTrace> {
        const fs::path path = dir / structure_alternative_dir({key, value}) / "trace.rtt";
        std::error_code missing;
        if (!fs::exists(path, missing)) {
            *why = "no alternative traced beside the trace (rtsim trace --alternatives writes " +
                   (fs::path(structure_alternative_dir({key, value})) / "trace.rtt").string() + ")";
            return nullptr;
        }
        try {
            auto a = std::make_unique<OpenedAlternative>();
            a->path = path.string();
            a->reader = std::make_unique<TraceReader>(a->path);
            TraceReader run(rtt);
            if (a->reader->section(SectionKind::rays).record_count != rays || !same_rays(run, *a->reader)) {
                *why = a->path + " holds other rays than the run's trace: trace it again with --alternatives";
                return nullptr;
            }
            const RunSetup setup = resolve_run(config, structure_facts(*a->reader));
            a->owned_accel = load_accel(read_accel_image(*a->reader), a->path);
            if (a->owned_accel->frame_count() > 1) {
                *why = "the alternative is animated: its frames are not estimated";
                return nullptr;
            }
            const TraversalConfig& t = setup.config.traversal;
            a->owned_map = std::make_unique<MemoryMap>(a->owned_accel->image().end_address(), rays,
                                                       uint64_t(t.units) * t.contexts(),
                                                       a->owned_accel->max_stack_entries(), t.stack_entry_bytes);
            a->accel = a->owned_accel.get();
            a->map = a->owned_map.get();
            a->config = setup.config;
            a->step = setup.step;
            a->rays = rays;
            a->identity = trace_identity(*a->reader);
            TraceReader* reader = a->reader.get();
            a->sample_stream = [reader](uint64_t first, uint64_t n, uint64_t sample) -> std::unique_ptr<RayStream> {
                return std::make_unique<SampleStream>(*reader, first, n, sample);
            };
            return a;
        } catch (const std::exception& e) {  // a bad file, or the filesystem's own errors
            *why = e.what();
            return nullptr;
        }
    };
}

}  // namespace rtsim
