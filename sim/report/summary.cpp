#include "sim/report/summary.h"

#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <string>
#include <ctime>

#include "rtl_model/isect/pipeline.h"
#include "rtl_model/mem/mem_stats.h"
#include "sim/report/summary_schema.h"
#include "traces/common/build_info.h"

namespace rtsim {

using nlohmann::json;

namespace {

/// A number a block declares (`block`), 0 when the level wrote null.
double number(const StatBlock& block, const json& stats, const char* key) {
    const json& v = StatsReader(block, stats)[key];
    return v.is_number() ? v.get<double>() : 0.0;
}

/// Hit rate over all caches of a level (reads served, including merged misses, over reads).
json hit_rate(const json& caches) {
    double reads = 0, served = 0;
    for (const json& c : caches) {
        reads += number(cache_stats(), c, "reads");
        served += number(cache_stats(), c, "read_hits") + number(cache_stats(), c, "merged");
    }
    return reads > 0 ? json(served / reads) : json(nullptr);
}

/// Mean of a stat over the blocks of a group ({"box_0": {...}, ...}) that all declare it in `block`.
/// The stats every traversal unit writes, by its registered path (a report reads declared stats,
/// never a unit kind).
const StatBlock& unit_block() { return registered_stat_block("model.units.<unit>"); }

json mean_of(const json& group, const StatBlock& block, const char* key) {
    if (!group.is_object() || group.empty()) return nullptr;
    double sum = 0, n = 0;
    for (const json& b : group) {
        const json& v = StatsReader(block, b)[key];
        if (!v.is_number()) continue;  // null: this level does not produce it
        sum += v.get<double>();
        ++n;
    }
    return n > 0 ? json(sum / n) : json(nullptr);
}

/// Active lanes / lane slots over the units' warp steps; null when no unit runs warps.
json simd_efficiency(const json& units) {
    double active = 0, slots = 0;
    bool simt = false;
    for (const json& u : units) {
        const StatsReader r(unit_block(), u);
        if (!u.contains("lane_slots")) continue;
        simt = true;
        active += r["active_lanes"].get<double>();
        slots += r["lane_slots"].get<double>();
    }
    if (!simt) return nullptr;
    return slots > 0 ? active / slots : 0.0;
}

/// Peak resident memory of this process's address space (VmHWM). getrusage's ru_maxrss would
/// also count the parent's pages a forked child held before exec (a Python caller's, say).
double peak_memory_mib() {
    std::ifstream status("/proc/self/status");
    for (std::string line; std::getline(status, line);)
        if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;  // kB
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return double(usage.ru_maxrss) / 1024.0;
}

}  // namespace

json summarize(const SimConfig& c, uint64_t cycles, uint64_t rays, const json& model, const CheckTotals& checker,
               double wall) {
    json s = {{"rays", rays},
              {"fidelity", kFidelityChoices.name(c.fidelity)},
              {"hit_mismatches", checker.hit_mismatches},
              {"work_mismatches", checker.work_mismatches},
              {"wall_seconds", wall},
              {"peak_memory_mib", peak_memory_mib()},
              {"simulated_rays_per_wall_second", wall > 0 ? double(rays) / wall : 0.0}};
    if (c.fidelity == Fidelity::functional) {
        // Every level reports the same keys; what the functional level cannot know is null
        // (the keys summary_schema.cpp marks as timed; the energy and verdict steps add theirs).
        for (const StatDecl& d : summary_stats().stats)
            if (d.timed) s[d.key] = nullptr;
        return s;
    }
    double seconds = double(cycles) / (c.clock_ghz * 1e9);
    s["cycles"] = cycles;
    s["seconds"] = seconds;
    s["rays_per_second"] = seconds > 0 ? double(rays) / seconds : 0.0;
    s["mrays_per_second"] = seconds > 0 ? double(rays) / seconds / 1e6 : 0.0;
    s["avg_ray_latency_cycles"] = checker.mean_latency_cycles;
    s["unit_busy_fraction"] = mean_of(model.value("units", json::object()), unit_block(), "busy_fraction");
    if (const json simd = simd_efficiency(model.value("units", json::object())); !simd.is_null())
        s["simd_efficiency"] = simd;
    s["box_utilization"] = mean_of(model.value("box", json::object()), pipeline_stats(), "utilization");
    s["triangle_utilization"] = mean_of(model.value("triangle", json::object()), pipeline_stats(), "utilization");
    if (model.contains("shading")) {
        // The frame (docs/shading.md): its headline figures beside the RT unit's.
        const json& sh = model["shading"];
        s["frame_ms"] = sh["frame_ms"];
        s["shading_share"] = sh["shading_share"];
        s["frame_speedup_2x_rt"] = sh["amdahl"]["speedup_2x_rt"];
        s["shading_divergence"] = sh["divergence"];
        s["shading_simd_efficiency"] = sh["simd_efficiency"];
        if (!sh["tex_hit_rate"].is_null()) s["tex_hit_rate"] = sh["tex_hit_rate"];
    }
    s["l1_hit_rate"] = model.contains("l1") ? hit_rate(model["l1"]) : json(nullptr);
    s["l2_hit_rate"] = model.contains("l2") ? hit_rate(json::array({model["l2"]})) : json(nullptr);
    if (model.contains("dram")) {
        const StatsReader d(dram_stats(), model["dram"]);
        double bytes = d["read_bytes"].get<double>() + d["write_bytes"].get<double>();
        s["dram_bytes"] = bytes;
        s["dram_bytes_per_ray"] = rays ? bytes / double(rays) : 0.0;
        s["dram_bandwidth_gbps"] = d["bandwidth_gbps"];
        s["dram_bandwidth_utilization"] = d["bandwidth_utilization"];
    } else {
        s["dram_bytes"] = 0;
        s["dram_bytes_per_ray"] = 0;
        s["dram_bandwidth_gbps"] = 0;
        s["dram_bandwidth_utilization"] = 0;
    }
    return s;
}

json provenance(const std::string& command_line, const std::string& trace, const json& manifest, std::time_t started) {
    char host[256] = {};
    gethostname(host, sizeof(host) - 1);
    char when[64];
    std::strftime(when, sizeof(when), "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&started));
    return {{"rtsim_version", rtsim_version()},
            {"git", rtsim_git_hash()},
            {"command_line", command_line},
            {"host", host},
            {"started_utc", when},
            {"trace", trace},
            {"scene", manifest.value("scene", json::object()).value("name", "")},
            {"trace_git", manifest.value("git", "")}};
}

}  // namespace rtsim
