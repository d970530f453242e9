#pragma once
// One simulation: a trace and a config in, RUN/stats.json, RUN/config.resolved.json and
// RUN/provenance.json out (docs/architecture.md, rule 5). SystemC elaborates once per process, so this runs at
// most once per process (rtsim-sim); Python runs many processes.
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "sim/config/config.h"

namespace rtsim {

struct SimOptions {
    std::string trace;    ///< trace folder (with trace.rtt and manifest.json) or a .rtt file
    SimConfig config;
    std::string out_dir;  ///< created if missing
    bool timeline = false;
    /// Also write the requests that reached DRAM (RUN/dram_trace.dramsim3.txt, dram_requests.csv,
    /// dram_trace.json), for replaying in another DRAM simulator (docs/model.md, "Against DRAMsim3"); timed levels only.
    bool dram_trace = false;
    bool progress = false;  ///< JSON progress lines on stderr: {"progress": done, "total": n}
    bool verdict = true;    ///< name the bottleneck and estimate what relaxing it buys (sim/report/verdict.h)
    /// Re-run the verdict's top knobs and co-limit, each in its own process (verdict_check.h)
    bool check_verdict = false;
    std::string command_line;
};

struct SimOutcome {
    nlohmann::json stats;
    int exit_code = 0;  ///< 0, or 3 when any hit or work mismatched the reference
};

/// Runs the simulation at config.fidelity. Throws rtsim::Error on bad input (trace, config).
SimOutcome run_simulation(const SimOptions& options);

}  // namespace rtsim
