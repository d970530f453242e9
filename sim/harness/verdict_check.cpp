#include "sim/harness/verdict_check.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "sim/harness/run_files.h"
#include "sim/report/verdict_knobs.h"
#include "traces/accel/accel.h"
#include "traces/common/error.h"

extern char** environ;

namespace rtsim {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

/// One re-run: the `--set`s, the estimate, and for another structure its trace beside the run's.
struct Candidate {
    std::vector<std::string> sets;
    json estimated;
    std::string trace;  ///< "" for the run's own trace
};

/// The candidates to measure: the top three knobs (one `key=value` each), the best co-limit
/// (both at once) and the structural alternatives: the best estimated one (on its trace beside
/// the run's when it is another structure) and the best that needs no new trace, without repeats.
std::vector<Candidate> to_measure(const json& verdict, const std::string& rtt) {
    std::vector<Candidate> out;
    auto add = [&](Candidate c) {
        for (const Candidate& o : out)
            if (o.sets == c.sets) return;
        out.push_back(std::move(c));
    };
    for (const json& k : verdict.value("top", json::array()))
        add({{k["key"].get<std::string>() + "=" + value_text(k["to"])}, k["speedup"], ""});
    for (const json& co : verdict.value("co_limits", json::array())) {
        add({co["sets"].get<std::vector<std::string>>(), co["joint"], ""});
        break;
    }
    const json structural = verdict.value("structural", json::array());
    // The best estimated alternative (the list is best first): the one the verdict may name.
    for (const json& k : structural) {
        if (!k["speedup"].is_number() || k.contains("refused")) continue;
        const std::string set = k["key"].get<std::string>() + "=" + value_text(k["to"]);
        if (!k.value("trace", false)) {
            add({{set}, k["speedup"], ""});
        } else {
            const fs::path alt = fs::path(rtt).parent_path() /
                                 structure_alternative_dir({k["key"].get<std::string>(), value_text(k["to"])});
            add({{set}, k["speedup"], alt.string()});
        }
        break;
    }
    // The best structural alternative a re-run can measure with no new trace: the one the run's
    // cycle accounting points at most, first listed on a tie.
    const json* best = nullptr;
    for (const json& k : structural)
        if (!k.value("trace", false) && !k.contains("refused") &&
            (!best || k.value("evidence", 0.0) > best->value("evidence", 0.0)))
            best = &k;
    if (best) add({{(*best)["key"].get<std::string>() + "=" + value_text((*best)["to"])}, (*best)["speedup"], ""});
    return out;
}

/// Runs `argv` with stdout and stderr into `log`; its exit code (-1 when it could not start or died).
int run_process(const std::vector<std::string>& argv, const std::string& log) {
    posix_spawn_file_actions_t files;
    posix_spawn_file_actions_init(&files);
    posix_spawn_file_actions_addopen(&files, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&files, 1, 2);
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    pid_t pid = 0;
    const int err = posix_spawn(&pid, args[0], &files, nullptr, args.data(), environ);
    posix_spawn_file_actions_destroy(&files);
    if (err != 0) return -1;
    int status = 0;
    if (waitpid(pid, &status, 0) < 0 || !WIFEXITED(status)) return -1;
    return WEXITSTATUS(status);
}

double rays_per_second_of(const fs::path& run) {
    std::ifstream in(run / "stats.json");
    const json stats = json::parse(in, nullptr, false);
    if (stats.is_discarded()) return 0;
    const json& r = stats.value("summary", json::object()).value("rays_per_second", json(nullptr));
    return r.is_number() ? r.get<double>() : 0;
}

}  // namespace

json check_verdict(const SimOptions& o, const json& verdict, double base_rays_per_second) {
    std::error_code ec;
    const std::string exe = fs::read_symlink("/proc/self/exe", ec).string();
    require(!ec && !exe.empty(), "--check-verdict: cannot find this rtsim-sim executable (/proc/self/exe)");
    const fs::path config = fs::path(o.out_dir) / "config.resolved.json";
    json out = json::array();
    int n = 0;
    for (const Candidate& m : to_measure(verdict, trace_file(o.trace))) {
        const fs::path run = fs::path(o.out_dir) / "check" / std::to_string(++n);
        fs::create_directories(run);
        std::vector<std::string> argv = {exe, m.trace.empty() ? o.trace : m.trace, "--no-verdict", "-o", run.string()};
        if (m.trace.empty()) {
            argv.insert(argv.end(), {"--config", config.string()});
            for (const std::string& s : m.sets) argv.insert(argv.end(), {"--set", s});
        } else {
            // Another structure resolves the run's config afresh (its stack entries, say): the
            // config as given (run_inputs.cpp), not as resolved against this trace's structure.
            argv.insert(argv.end(), {"--config", (fs::path(o.out_dir) / "config.given.json").string()});
        }
        const int code = run_process(argv, (run / "log.txt").string());
        const double rps = code == 0 ? rays_per_second_of(run) : 0;
        json c = {{"sets", m.sets}, {"estimated", m.estimated}, {"run", run.string()}};
        if (!m.trace.empty()) c["trace"] = m.trace;
        c["measured"] = rps > 0 && base_rays_per_second > 0 ? json(rps / base_rays_per_second) : json(nullptr);
        if (code != 0)
            c["error"] = "rtsim-sim exited with " + std::to_string(code) + " (see " + (run / "log.txt").string() + ")";
        out.push_back(c);
    }
    std::stable_sort(out.begin(), out.end(), [](const json& a, const json& b) {
        const double x = a["measured"].is_number() ? a["measured"].get<double>() : 0;
        const double y = b["measured"].is_number() ? b["measured"].get<double>() : 0;
        return x > y;
    });
    return out;
}

}  // namespace rtsim
