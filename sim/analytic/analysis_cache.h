#pragma once
// Per-trace analyses kept beside the trace (docs/fidelity.md, "Sweeps at the analytic level"),
// so every rtsim-sim process of a sweep at the analytic level loads the analysis instead of
// redoing it: TRACE_FOLDER/analytic/<hash of key>.json.
//
// The key is everything the analysis depends on: the trace's content (file size, section table
// and every chunk's CRC32, read without reading the payload), the analysis version, the sample
// parameters, and the config fields that shape the access streams (units, ray contexts, dispatch
// policy, block and chunk, line size, on-chip stack entries and entry bytes). Cache sizes, ways,
// latencies, MSHRs, banks, pipelines and DRAM are not in it: they are evaluated per run.
//
// Concurrent processes (a sweep's workers) take an exclusive flock on the analysis's lock file
// while one of them computes it; the others then load it. Files are written to a temporary name
// and renamed, so a reader never sees half a file. RTSIM_ANALYTIC_CACHE=off disables the cache;
// RTSIM_ANALYTIC_CACHE=DIR keeps analyses in DIR instead (for read-only trace folders).
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "sim/config/config.h"
#include "sim/analytic/profile.h"
#include "traces/format/trace_reader.h"

namespace rtsim {

/// Content identity of a trace without reading its payload (hex digest).
std::string trace_identity(const TraceReader& reader);

/// The analysis key for a trace identity, config and sample.
nlohmann::json analysis_key(const SimConfig& config, const AnalyticConfig& sample, const std::string& identity);

/// Where the analysis for `key` of the trace at `rtt` lives ("" when caching is off).
std::string analysis_path(const std::string& rtt, const nlohmann::json& key);

/// The cached analysis at `path` if it exists and has exactly this key.
std::optional<AnalyticProfile> load_analysis(const std::string& path, const nlohmann::json& key);

/// Writes the analysis atomically (temporary file, rename); a failure to write is not an error
/// (the run goes on uncached) and returns false.
bool store_analysis(const std::string& path, const AnalyticProfile& profile);

/// An exclusive lock on PATH.lock for the lifetime of the object (no-op for an empty path or
/// when the folder cannot be created).
class AnalysisLock {
public:
    explicit AnalysisLock(const std::string& path);
    ~AnalysisLock();
    AnalysisLock(const AnalysisLock&) = delete;
    AnalysisLock& operator=(const AnalysisLock&) = delete;

private:
    int m_fd = -1;
};

}  // namespace rtsim
