// The one run loop of every level (docs/architecture.md, "One run loop"): resolve (run_inputs.h:
// the trace opened, the config matched against its structure once), build, run and check (the
// level's: level.h), report (here: the common keys, then every registered report block in order,
// sim/report/report_block.h), and the files written.
#include "sim/harness/simulate.h"

#include <filesystem>

#include "sim/harness/level.h"
#include "sim/harness/run_files.h"
#include "sim/harness/verdict_check.h"
#include "sim/report/report_block.h"
#include "sim/report/stats_schema.h"
#include "sim/report/summary.h"
#include "sim/sampling/sampling.h"

namespace rtsim {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

/// The level `config` runs at.
LevelResult run_level(RunInputs& in) {
    switch (in.config().fidelity) {
        case Fidelity::functional: return run_functional_level(in);
        case Fidelity::analytic: return run_analytic_level(in);
        case Fidelity::approx:
        case Fidelity::detailed: break;
    }
    return run_timed_level(in);
}

/// The report stage: stats.json from what the level ran, each report block's keys added by it.
SimOutcome report(RunInputs& in, LevelResult& level) {
    const SimOptions& o = in.options;
    const SimConfig& c = in.config();
    SimOutcome out;
    out.stats = {{"schema", "rtsim-stats/1"},
                 {"fidelity", kFidelityChoices.name(c.fidelity)},
                 {"summary", level.summary},
                 {"validation", level.validation},
                 {"latency", level.latency},
                 {"workload", level.workload},
                 {"instantiated", with_structure_blocks(level.instantiated, in.setup.structure)},
                 {"effects", in.manifest.value("workload", json::object()).value("effects", json::array())},
                 {"model", level.model},
                 {"provenance", provenance(o.command_line, in.rtt, in.manifest, in.started)}};
    if (!level.frames.is_null()) out.stats["frames"] = level.frames;
    const bool sampled = !level.sampling.is_null();
    if (sampled) out.stats["sampling"] = level.sampling;
    json& summary = out.stats["summary"];
    summary["sampled"] = sampled;
    // A sample that would be the whole trace is not taken (sample_covers_trace): say so, or a
    // sampling request ends in a full, exact run that reads like one that was never asked for.
    const bool timed = c.fidelity == Fidelity::approx || c.fidelity == Fidelity::detailed;
    if (!sampled && timed && c.sampling.enabled())
        summary["sampling_note"] = "sampling (" +
                                   (c.sampling.count ? "sampling.count " + std::to_string(c.sampling.count)
                                                     : "sampling.fraction " + json(c.sampling.fraction).dump()) +
                                   ") would cover the whole trace of " + std::to_string(level.rays) +
                                   " rays (or no sample of it fits two clusters of warm-up and measured rays): "
                                   "every ray was simulated, the figures are exact";
    summary["frames"] = level.frame_count;
    summary["resolved"] = in.setup.to_json();
    ReportInputs inputs{c, level.work, level.rays, in.setup.structure.kind, {}};
    if (o.verdict && level.judge && summary.value("rays", 0) > 0)
        inputs.verdict = [&]() {
            json verdict = level.judge(out.stats["model"]);
            if (o.check_verdict) {
                // The verdict's report block adds the re-runs to its text.
                verdict["check"] = check_verdict(o, verdict, out.stats["summary"].value("rays_per_second", 0.0));
            }
            return verdict;
        };
    for (const ReportBlock* b : report_blocks()) b->add(out.stats, inputs);
    check_run_stats(out.stats, sampled);  // every key declared once, by its producer (stats_schema.h)
    write_json(fs::path(o.out_dir) / "stats.json", out.stats);
    write_json(fs::path(o.out_dir) / "provenance.json", out.stats["provenance"]);
    out.exit_code = level.bad ? 3 : 0;
    return out;
}

}  // namespace

SimOutcome run_simulation(const SimOptions& options) {
    RunInputs in(options);  // resolve: every refusal of a combination is raised here
    LevelResult level = run_level(in);
    return report(in, level);
}

}  // namespace rtsim
