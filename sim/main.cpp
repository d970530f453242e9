// rtsim-sim: one simulation per process (SystemC elaborates once).
//   rtsim-sim TRACE [--config CFG.json] [--set key=value ...] -o RUN [--timeline] [--progress]
//   rtsim-sim --dump-defaults | --dump-schema | --dump-stats-schema
// Exit codes: 0 ok, 2 bad input (message names the file or field), 3 hits differ from the reference.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>

#include <CLI/CLI.hpp>
#include <systemc>

#include "sim/harness/simulate.h"
#include "sim/report/stats_schema.h"
#include "sim/resolve/resolve.h"
#include "traces/common/error.h"
#include "traces/common/files.h"

namespace {

rtsim::SimConfig load_config(const std::string& path, const std::vector<std::string>& sets) {
    rtsim::SimConfig config;
    if (!path.empty()) {
        rtsim::require_utf8_path(path, "--config");
        // A FIFO or /dev/zero is refused; a config is small (the defaults are 6 KB).
        const std::string text = rtsim::read_small_file(path, "config JSON file", 64u << 20);
        nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
        rtsim::require(!j.is_discarded(), path + ": not valid JSON");
        try {
            config = rtsim::config_from_json(j);
        } catch (const rtsim::Error& e) {
            throw rtsim::Error(path + ": " + e.what());
        }
    }
    for (const std::string& s : sets) rtsim::config_set(config, s);
    try {
        rtsim::validate(config);
    } catch (const rtsim::Error& e) {
        // Name the file the value came from, unless a --set assignment named in the message did.
        const std::string what = e.what();
        bool from_set = false;
        for (const std::string& s : sets)
            from_set = from_set || what.find("'" + s.substr(0, s.find('=')) + "'") != std::string::npos;
        if (path.empty() || from_set) throw;
        throw rtsim::Error(path + ": " + what);
    }
    return config;
}

}  // namespace

int sc_main(int argc, char** argv) {
    CLI::App app{"rtsim-sim: replays a ray trace on the SystemC accelerator model"};
    std::string trace, config_path, out_dir;
    std::vector<std::string> sets;
    bool timeline = false, progress = false, dump_defaults = false, dump_schema = false, dump_stats_schema = false,
         no_verdict = false, check_verdict = false, capabilities = false, capabilities_md = false;
    std::string check_runs;
    app.add_option("trace", trace, "Trace folder (from rtsim trace) or .rtt file");
    app.add_option("--config", config_path, "Config JSON (defaults for missing keys)");
    app.add_option("--set", sets, "Override a config key: key.path=value (repeatable)");
    app.add_option("-o,--out", out_dir, "Run folder for stats.json, config.resolved.json, provenance.json");
    app.add_flag("--timeline", timeline, "Also write timeline.json (Chrome/Perfetto trace events)");
    bool dram_trace = false;
    app.add_flag("--dram-trace", dram_trace,
                 "Also write the requests that reached DRAM as a DRAMsim3 trace and a CSV (RUN/dram_trace.*; "
                 "approx and detailed levels)");
    app.add_flag("--progress", progress, "Print JSON progress lines on stderr");
    app.add_flag("--no-verdict", no_verdict, "Skip the bottleneck verdict (its analytic estimates on a sample of the trace)");
    app.add_flag("--check-verdict", check_verdict,
                 "Re-run the verdict's top three knobs and its co-limit, each in its own process (RUN/check/N), "
                 "and report measured against estimated gains");
    app.add_flag("--dump-defaults", dump_defaults, "Print the default config as JSON and exit");
    app.add_flag("--dump-schema", dump_schema, "Print every config field with default, unit, range, doc");
    app.add_flag("--dump-stats-schema", dump_stats_schema, "Print every stats.json block's declared keys with unit and meaning");
    bool dump_names = false;
    app.add_flag("--dump-names", dump_names,
                 "Print the names the C++ side declares and Python reads (ray kinds, data kinds, operation kinds, "
                 "unit kinds, structures) as JSON");
    app.add_flag("--capabilities", capabilities, "Print what composes with what (rules, structures, unit kinds, levels) as JSON");
    app.add_flag("--capabilities-markdown", capabilities_md, "Print the same as Markdown (docs/capabilities.md)");
    app.add_option("--check-runs", check_runs,
                   "Resolve each run of a JSON list [{config, accel, blas_kind, compressed_leaves}] before any trace "
                   "exists (sweeps check their specs this way) and print [{ok, error, resolved}]");
    CLI11_PARSE(app, argc, argv);
    try {
        if (dump_stats_schema) {
            std::cout << rtsim::stats_schema_json().dump(2) << "\n";
            return 0;
        }
        if (dump_names) {
            std::cout << rtsim::declared_names().dump(2) << "\n";
            return 0;
        }
        if (capabilities || capabilities_md) {
            std::cout << (capabilities ? rtsim::capability_table().dump(2) : rtsim::capability_markdown()) << "\n";
            return 0;
        }
        if (!check_runs.empty()) {
            std::cout << rtsim::check_runs(check_runs).dump() << "\n";
            return 0;
        }
        if (dump_defaults || dump_schema) {
            std::cout << (dump_schema ? rtsim::config_schema() : rtsim::config_to_json(rtsim::SimConfig{})).dump(2) << "\n";
            return 0;
        }
        rtsim::require(!trace.empty(), "no trace given (rtsim-sim TRACE -o RUN)");
        rtsim::require(!out_dir.empty(), "no run folder given (-o RUN)");
        rtsim::require_utf8_path(trace, "trace");
        rtsim::require_utf8_path(out_dir, "run folder (-o)");
        sc_core::sc_set_time_resolution(1, sc_core::SC_NS);  // one SystemC ns per cycle
        rtsim::SimOptions o;
        o.trace = trace;
        o.config = load_config(config_path, sets);
        rtsim::make_output_folder(out_dir, "run");
        o.out_dir = out_dir;
        o.timeline = timeline;
        o.dram_trace = dram_trace;
        // Only the timed levels send requests to a DRAM model; elsewhere the flag would do nothing.
        rtsim::require(!dram_trace || o.config.fidelity == rtsim::Fidelity::approx ||
                           o.config.fidelity == rtsim::Fidelity::detailed,
                       "--dram-trace needs a timed level (fidelity approx or detailed)");
        o.progress = progress;
        o.verdict = !no_verdict;
        o.check_verdict = check_verdict && !no_verdict;
        for (int i = 0; i < argc; ++i) o.command_line += (i ? " " : "") + std::string(argv[i]);
        rtsim::SimOutcome r = rtsim::run_simulation(o);
        const auto& s = r.stats["summary"];
        std::cerr << "rtsim-sim: " << s["rays"] << " rays, " << s["hit_mismatches"] << " hit mismatches, "
                  << s["work_mismatches"] << " work mismatches -> " << out_dir << "/stats.json\n";
        if (s.contains("sampling_note"))
            std::cerr << "rtsim-sim: note: " << s["sampling_note"].get<std::string>() << "\n";
        if (r.stats.contains("sampling"))
            for (const auto& why : r.stats["sampling"]["caveats"])
                std::cerr << "rtsim-sim: warning: sample too small to trust: " << why.get<std::string>() << "\n";
        return r.exit_code;
    } catch (const rtsim::Error& e) {
        std::cerr << "rtsim-sim: error: " << e.what() << "\n";
        return 2;
    } catch (const std::filesystem::filesystem_error& e) {
        // A folder or file that cannot be made or read after the checks above (a race).
        std::cerr << "rtsim-sim: error: " << e.what() << "\n";
        return 2;
    } catch (const sc_core::sc_report& e) {
        // An error thrown inside a SystemC process reaches us wrapped in a report (E549); its
        // text carries the original message (file, field or ray).
        std::cerr << "rtsim-sim: error: " << e.what() << "\n";
        return 2;
    }
}

int main(int argc, char** argv) {
    setenv("SYSTEMC_DISABLE_COPYRIGHT_MESSAGE", "1", 1);
    return sc_core::sc_elab_and_sim(argc, argv);
}
