#pragma once
// The first stages of every level's run (docs/architecture.md, "One run loop"): resolve (the
// trace opened, its structure's facts read, the config matched against them once:
// sim/resolve/resolve.h) and build (the structure loaded and checked, the frames, the workload
// scanned, the memory map). The levels (level.h) run on what these hand them.
#include <chrono>
#include <ctime>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rtl_model/common/memory_map.h"
#include "rtl_model/top/top.h"
#include "sim/harness/simulate.h"
#include "sim/report/verdict.h"
#include "sim/resolve/resolve.h"
#include "traces/accel/accel.h"
#include "traces/format/trace_reader.h"
#include "traces/format/trace_checks.h"

namespace rtsim {

/// The resolve stage's outcome: what every level starts from.
struct RunInputs {
    explicit RunInputs(const SimOptions& options);

    const SimOptions& options;
    std::chrono::steady_clock::time_point t0;
    std::time_t started;
    std::string rtt;  ///< the trace file
    TraceReader reader;
    nlohmann::json manifest;
    RunSetup setup;  ///< the resolved config, step options, unit kind and structure facts
    const SimConfig& config() const { return setup.config; }
    double wall_seconds() const;
};

/// The build stage's outcome: the structure the levels step, and what goes with it.
struct BuiltRun {
    std::unique_ptr<Accel> accel;
    std::vector<FrameRecord> frames;
    WorkloadFeatures features;
    nlohmann::json workload;  ///< stats.json "workload" (one pass over the rays)
    uint64_t rays = 0;
    std::unique_ptr<MemoryMap> map;
};

/// Loads and checks the structure (load_accel), its frames, the host memory the model needs, the
/// workload and every chunk's CRC; spill areas per ray when `per_ray_spills` (rays move between
/// units), else per ray context.
BuiltRun build_run(RunInputs& in, bool per_ray_spills);

/// The hit checker's progress lines on stderr ({"progress": done, "total": n}) when the run asked
/// for them (SimOptions::progress), else none.
std::function<void(uint64_t done, uint64_t total)> progress_of(const SimOptions& options);

/// The verdict's view of the run's unit kind (its knobs, the kind its estimates stand in with).
UnitTraits unit_traits(const RunSetup& setup);
/// What the verdict's structural knobs need of the run's structure (verdict_knobs.h).
StructureTraits structure_traits(const RunInputs& in);
/// A level's instantiated blocks with the structure's own (its decoders: technique_cost.h), which
/// the area model prices.
nlohmann::json with_structure_blocks(nlohmann::json instantiated, const StructureFacts& structure);
/// A verdict context over `built` (the sample the verdict's own analysis steps read from the trace).
VerdictContext verdict_context(RunInputs& in, const BuiltRun& built, const nlohmann::json& model,
                               const nlohmann::json& instantiated);

}  // namespace rtsim
