#include "sim/report/roofline.h"
#include "sim/report/report_block.h"

#include "rtl_model/isect/pipeline.h"
#include "sim/report/resources.h"

namespace rtsim {

using nlohmann::json;

namespace {

double number(const json& j, const char* key) {
    const json& v = j.value(key, json(nullptr));
    return v.is_number() ? v.get<double>() : 0.0;
}

/// One cache level's MSHR ceiling by Little's law: its MSHRs can keep at most `mshrs` lines in
/// flight, each for the misses' mean hold time, so the level moves at most mshrs x line bytes /
/// hold bytes per cycle; over its miss bytes per ray, that many rays. (In rays: rays x mshrs x
/// clock / the misses' summed hold cycles, a bound no run exceeds since mean occupancy is at most
/// the MSHRs.) Null when the level kept no MSHR time (analytic, or no misses).
json mshr_ceiling(const std::vector<const json*>& caches, double mshrs, double line_bytes, double rays, double hz) {
    double busy = 0, misses = 0;
    for (const json* c : caches) {
        busy += number(*c, "mshr_busy_cycles");
        misses += number(*c, "reads") - number(*c, "read_hits") - number(*c, "merged");
    }
    if (busy <= 0 || misses <= 0) return nullptr;
    const double latency = busy / misses;
    return {{"rays_per_second", rays * mshrs * hz / busy},
            {"mshrs", mshrs},
            {"line_bytes", line_bytes},
            {"mean_hold_cycles", latency},
            {"bytes_per_second", mshrs * line_bytes / latency * hz},
            {"miss_bytes_per_ray", misses * line_bytes / rays}};
}

/// The memory levels' ceilings: MSHRs at each level (Little's law) and the L2's bank bandwidth.
/// At the analytic level they are its closed form's own bounds (cycles for the whole run).
void memory_ceilings(const SimConfig& c, const json& model, double rays, double hz, json* ceilings, json* little) {
    if (c.ideal_memory || !model.contains("l2")) return;
    const json& bounds = model.value("analytic", json::object()).value("bounds", json::object());
    if (c.fidelity == Fidelity::analytic) {
        for (const char* name : {"l1_mshrs", "l2_mshrs", "l2_banks"})
            if (bounds.contains(name) && bounds[name].is_number() && bounds[name].get<double>() > 0)
                (*ceilings)[name] =
                    rays * hz / bounds[name].get<double>();
        return;
    }
    std::vector<const json*> l1s;
    if (model.contains("l1"))
        for (const json& l1 : model.at("l1")) l1s.push_back(&l1);
    const double line = c.l1.line_bytes;
    const json l1 = mshr_ceiling(l1s, double(c.l1.mshrs) * c.traversal.units, line, rays, hz);
    const json& l2_stats = model.at("l2");
    const json l2 = mshr_ceiling({&l2_stats}, c.l2.mshrs, line, rays, hz);
    if (!l1.is_null()) (*ceilings)["l1_mshrs"] = l1["rays_per_second"], (*little)["l1"] = l1;
    if (!l2.is_null()) (*ceilings)["l2_mshrs"] = l2["rays_per_second"], (*little)["l2"] = l2;
    const double l2_lines = number(l2_stats, "reads") + number(l2_stats, "writes");
    if (l2_lines > 0) (*ceilings)["l2_banks"] = double(c.l2.banks) / c.l2.bank_cycles * hz / (l2_lines / rays);
}

}  // namespace

json roofline_json(const SimConfig& c, const json& summary, const json& model) {
    if (c.fidelity == Fidelity::functional || !summary.value("rays", json(0)).is_number()) return nullptr;
    const double rays = summary.value("rays", 0.0), hz = c.clock_ghz * 1e9;
    if (rays <= 0) return nullptr;
    json ceilings = json::object();
    const json bytes = summary.value("dram_bytes_per_ray", json(nullptr));
    if (bytes.is_number() && bytes.get<double>() > 0 && !c.ideal_memory)
        ceilings["dram"] = double(c.dram.bytes_per_cycle) * c.dram.channels * hz / bytes.get<double>();
    for (int k = 0; k < kOpKindCount; ++k) {
        const char* name = op_kind_name(OpKind(k));
        if (!model.contains(name)) continue;
        double issues = 0, pipelines = 0;
        for (const json& p : model[name]) {
            const StatsReader pipe(pipeline_stats(), p);
            issues += pipe["issues"].get<double>();
            pipelines += pipe["pipelines"].get<double>();
        }
        if (issues > 0) ceilings[name] = pipelines * hz / c.pipeline(OpKind(k)).initiation_interval / (issues / rays);
    }
    double steps = 0;
    for (const json& u : model.value("units", json::object())) steps += StatsReader(registered_stat_block("model.units.<unit>"), u)["steps"].get<double>();
    if (steps > 0) ceilings["scheduler"] = double(c.traversal.units) * hz / c.traversal.issue_cycles / (steps / rays);
    json little = json::object();
    memory_ceilings(c, model, rays, hz, &ceilings, &little);
    std::string bound;
    double lowest = 0;
    for (auto it = ceilings.begin(); it != ceilings.end(); ++it)
        if (bound.empty() || it.value().get<double>() < lowest) {
            lowest = it.value().get<double>();
            bound = it.key();
        }
    // A miss holds its MSHR while it queues for a DRAM channel, so saturated channels fill the
    // MSHRs too and their Little's-law ceiling meets the DRAM's: within 2% of it, the DRAM binds.
    if ((bound == "l1_mshrs" || bound == "l2_mshrs") && ceilings.contains("dram") &&
        ceilings["dram"].get<double>() <= lowest * 1.02) {
        bound = "dram";
        lowest = ceilings["dram"].get<double>();
    }
    return {{"dram_bytes_per_ray", bytes},
            {"rays_per_second", summary.value("rays_per_second", json(nullptr))},
            {"peak_dram_bytes_per_second", double(c.dram.bytes_per_cycle) * c.dram.channels * hz},
            {"ceilings", ceilings},
            {"bound", bound},
            {"bound_label", bound.empty() ? json(nullptr) : json(resource_label(bound))},
            {"bound_rays_per_second", bound.empty() ? json(nullptr) : json(lowest)},
            {"mshr_little", little}};
}

const StatBlock& roofline_stats() {
    static const StatBlock block{
        "roofline",
        {
            {"rays_per_second", "rays/s", "achieved (`summary.rays_per_second`)"},
            {"ceilings", "rays/s", "`{resource: rays/s}` what each resource alone allows: `dram` = peak DRAM bytes/s over `dram_bytes_per_ray`, `box`, `triangle`, ... = pipeline issue slots/s over issues per ray, `scheduler` = units x clock / (steps per ray x `issue_cycles`), `l1_mshrs` and `l2_mshrs` = Little's law, MSHRs x line bytes / the misses' mean MSHR hold time, over miss bytes per ray (`mshr_little`), `l2_banks` = L2 banks / `bank_cycles` x clock over L2 line accesses per ray; at the analytic level the memory ceilings are its closed form's bounds"},
            {"bound", "", "the lowest ceiling's name, in the verdict's vocabulary (`verdict.binding`, `model.analytic.bounds`); `dram` when an MSHR ceiling is lowest but the DRAM's is within 2% of it (the MSHRs are held by the DRAM's queue)"},
            {"bound_label", "", "the same in words, as the verdict labels it"},
            {"bound_rays_per_second", "rays/s", "the bound's ceiling (the lowest, or the DRAM's within 2% of it); the run can never be faster than the lowest (tested)"},
            {"dram_bytes_per_ray", "bytes/ray", "as `summary.dram_bytes_per_ray`"},
            {"peak_dram_bytes_per_second", "B/s", "`channels x bytes_per_cycle x clock`"},
            {"mshr_little", "", "timed levels: `l1` and `l2`, each with `rays_per_second` (the ceiling), `mshrs` (all units' at the L1), `line_bytes`, `mean_hold_cycles` (loaded: a miss's MSHR time), `bytes_per_second` (`mshrs x line_bytes / mean_hold_cycles x clock`) and `miss_bytes_per_ray`; empty when no level kept MSHR time"},
        }};
    return block;
}

RTSIM_REGISTER_STAT_BLOCK(roofline_stats)

namespace {

ReportBlock roofline_report() {
    ReportBlock b;
    b.name = "roofline";
    b.order = 60;
    b.add = [](json& stats, const ReportInputs& in) {
        stats["roofline"] = roofline_json(in.config, stats["summary"], stats.value("model", json::object()));
    };
    b.keys = {{"roofline", roofline_stats}};
    return b;
}

}  // namespace

RTSIM_REGISTER_REPORT_BLOCK(roofline_report())

}  // namespace rtsim
