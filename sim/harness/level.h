#pragma once
// The run and check stages of each fidelity level (docs/fidelity.md): each level takes what the
// resolve stage opened (run_inputs.h), builds and runs what it needs, checks every ray it runs
// against the reference, and hands the report stage (simulate.cpp) a LevelResult. Which level
// runs is the config's fidelity; nothing else in the run loop depends on it.
#include <cstdint>
#include <functional>

#include <nlohmann/json.hpp>

#include "rtl_model/common/interfaces.h"
#include "sim/harness/run_inputs.h"
#include "traces/common/work_counts.h"

namespace rtsim {

struct LevelResult {
    Cycle cycles = 0;
    nlohmann::json summary;  ///< summarize()'s, with what the level knows beyond it
    nlohmann::json validation, latency, workload;
    nlohmann::json instantiated = nlohmann::json::array();
    nlohmann::json model = nlohmann::json::object();
    nlohmann::json frames;    ///< each frame's figures; null where the level replays no frames
    size_t frame_count = 1;
    nlohmann::json sampling;  ///< a sampled run's estimate; null otherwise
    WorkTotals work;          ///< every checked ray's work (energy and area)
    uint64_t rays = 0;        ///< rays the work is of
    bool bad = false;         ///< a hit or work mismatch
    /// The level's verdict from the run's model stats; null where the level has none.
    std::function<nlohmann::json(const nlohmann::json& model)> judge;
};

/// functional: the reference walks, no time.
LevelResult run_functional_level(RunInputs& in);
/// approx and detailed: the SystemC model, the whole trace or a sample of it.
LevelResult run_timed_level(RunInputs& in);
/// analytic: a closed form over a per-trace analysis (statistical or functional caches).
LevelResult run_analytic_level(RunInputs& in);

}  // namespace rtsim
