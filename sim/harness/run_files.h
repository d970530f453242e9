#pragma once
// What every level's run does with its files (simulate.cpp, run_analytic.cpp): find the trace,
// read and check its manifest, scan its rays once, write JSON outputs. One copy, so every level
// refuses the same bad input with the same message (docs/validation.md).
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "rtl_model/common/stats.h"
#include "rtl_model/top/top.h"
#include "traces/format/trace_reader.h"

namespace rtsim {

/// The .rtt file of a trace folder or file; throws rtsim::Error naming the path if absent.
std::string trace_file(const std::string& path);

/// The trace's manifest.json ({} when there is none), checked: an object whose keys the harness
/// reads have their documented types. Throws rtsim::Error naming the file and key.
nlohmann::json read_manifest(const std::string& rtt);

/// One pass over the rays: counts per kind and occlusion rays (stats "workload"); refuses a ray
/// of unknown kind naming the trace and the ray. `features` (optional) gets what the model needs.
nlohmann::json scan_workload(TraceReader& reader, WorkloadFeatures* features = nullptr);

/// Writes `j` (indented) to `path`; throws rtsim::Error naming it if it cannot.
void write_json(const std::filesystem::path& path, const nlohmann::json& j);

/// stats.json "workload", declared once.
const StatBlock& workload_stats();

}  // namespace rtsim
