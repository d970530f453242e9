// Is this run big enough to answer its question? (docs/treelets.md, "How many rays a treelet
// study needs"; docs/stats.md, "study_size"). A run can be correct and still answer nothing:
// a ray buffer that never filled measures admission, not treelets (its queues never grew, every
// pick was a drain pick); a machine that spent much of its time filling and draining measures
// the trace's length, not the design; a sample too small for its warm-up measures cold caches.
// Each such finding names the trace size that would do, so the study can be re-run at that size.
#include <algorithm>
#include <cmath>
#include <string>

#include "rtl_model/common/stats.h"
#include "sim/report/report_block.h"

namespace rtsim {

using nlohmann::json;

namespace {

/// A ray buffer whose most occupancy stayed under this share of its capacity never filled.
constexpr double kFilled = 0.5;
/// Picks that are drain picks above this share: the queues never reached the threshold.
constexpr double kDrainPicks = 0.9;
/// How many times (capacity + contexts) a treelet study needs: the buffer fills in about one
/// capacity's worth of admissions and drains in another, so at this many the full buffer holds
/// for most of the run (fill and drain under about a third of it).
constexpr double kTreeletRaysFactor = 6;
/// Drain (contexts idle because the trace ran out) above this share of context cycles: the run
/// measures its own length; the rays that bring it under kDrainTarget are named.
constexpr double kDrainWarn = 0.10, kDrainTarget = 0.05;

std::string ray_count(double x) {
    char buf[64];
    const long long v = std::llround(x);
    std::string digits = std::to_string(v), out;
    for (size_t i = 0; i < digits.size(); ++i) {
        if (i && (digits.size() - i) % 3 == 0) out += ',';
        out += digits[i];
    }
    std::snprintf(buf, sizeof buf, "%s", out.c_str());
    return buf;
}

/// Rounds a ray count up to two significant figures (a trace size to ask for).
double round_up_rays(double rays) {
    if (rays <= 0) return 0;
    const double scale = std::pow(10.0, std::floor(std::log10(rays)) - 1);
    return std::ceil(rays / scale) * scale;
}

double size_number(const json& j, const char* key) {
    const json& v = j.is_object() ? j.value(key, json(nullptr)) : json(nullptr);
    return v.is_number() ? v.get<double>() : 0.0;
}

void ray_buffer_findings(const SimConfig& c, const json& stats, double rays, json* out) {
    const json& rb = stats.value("model", json::object()).value("ray_buffer", json(nullptr));
    if (!c.treelets.enabled || !rb.is_object()) return;
    const double capacity = size_number(rb, "capacity_rays"), most = size_number(rb, "max_occupancy");
    const double picks = size_number(rb, "picks"), drains = size_number(rb, "drain_picks");
    if (capacity <= 0) return;
    const double contexts = double(c.traversal.units) * c.traversal.contexts();
    const double needed = round_up_rays(kTreeletRaysFactor * (capacity + contexts));
    const bool never_filled = most < kFilled * capacity;
    const bool all_drain = picks > 0 && drains >= kDrainPicks * picks;
    if (!never_filled && !all_drain) return;
    std::string text = "the ray buffer never filled: at most " + ray_count(most) + " of its " + ray_count(capacity) +
                       " rays waited";
    if (all_drain) {
        char buf[96];
        std::snprintf(buf, sizeof buf, "%.0f%% of %s picks were drain picks, %.2f rays per pick", 100.0 * drains / picks,
                      ray_count(picks).c_str(), size_number(rb, "avg_queue_rays_at_pick"));
        text += std::string("; ") + buf;
    }
    json f = {{"kind", "ray_buffer_not_filled"}, {"max_occupancy", most}, {"capacity_rays", capacity}};
    if (rays < needed) {
        text += "; the trace's " + ray_count(rays) + " rays are too few: a treelet study needs about " + ray_count(needed) +
                " (" + ray_count(kTreeletRaysFactor) + " x the buffer's and the contexts' rays, docs/treelets.md)";
        f["rays_needed"] = needed;
    } else {
        text += "; the trace has enough rays (" + ray_count(rays) + "): admission, not the trace, kept it empty "
                "(treelets.admit_outstanding " + std::to_string(c.treelets.admit_outstanding) +
                "): this measures admission, not treelet reuse";
        f["rays_needed"] = nullptr;
    }
    f["text"] = text;
    out->push_back(f);
}

void drain_finding(const json& stats, double rays, json* out) {
    const json& fractions = stats.value("model", json::object()).value("cycle_accounting", json::object())
                                .value("fractions", json::object());
    const double tail = size_number(fractions, "tail");
    if (tail <= kDrainWarn) return;
    // The drain's cycles are about fixed (the last rays' latency): their share falls as 1 / rays.
    const double needed = round_up_rays(rays * tail / kDrainTarget);
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.0f%%", 100.0 * tail);
    out->push_back({{"kind", "drain_dominates"},
                    {"tail_fraction", tail},
                    {"rays_needed", needed},
                    {"text", std::string("the machine was draining (contexts idle, the trace run out) ") + buf +
                                 " of its context cycles: the figures measure the trace's length as much as the "
                                 "design; about " + ray_count(needed) + " rays bring the drain under 5%"}});
}

void sampling_findings(const json& stats, double rays, json* out) {
    const json& s = stats.value("sampling", json(nullptr));
    if (!s.is_object()) return;
    const double warm = size_number(s, "warmup_rays"), target = size_number(s, "warmup_target_rays");
    const double clusters = size_number(s, "clusters");
    for (const json& caveat : s.value("caveats", json::array())) {
        json f = {{"kind", "sample_too_short"}, {"text", "sample: " + caveat.get<std::string>()}};
        // More rays in the trace give each cluster room for its warm-up at the same fraction.
        if (target > warm && warm > 0) f["rays_needed"] = round_up_rays(rays * target / warm);
        else if (clusters > 0 && clusters < 10) f["rays_needed"] = round_up_rays(rays * 10.0 / clusters);
        else f["rays_needed"] = nullptr;
        out->push_back(f);
    }
}

json study_size(const SimConfig& c, const json& stats) {
    const double rays = size_number(stats.value("summary", json::object()), "rays");
    json findings = json::array();
    if (c.fidelity == Fidelity::approx || c.fidelity == Fidelity::detailed) {
        ray_buffer_findings(c, stats, rays, &findings);
        drain_finding(stats, rays, &findings);
    }
    sampling_findings(stats, rays, &findings);
    double needed = 0;
    for (const json& f : findings)
        if (f.value("rays_needed", json(nullptr)).is_number()) needed = std::max(needed, f["rays_needed"].get<double>());
    return {{"too_small", !findings.empty()},
            {"trace_rays", rays},
            {"rays_needed", needed > 0 ? json(needed) : json(nullptr)},
            {"findings", findings}};
}

const StatBlock& study_size_stats() {
    static const StatBlock block{
        "study_size",
        {
            {"too_small", "bool", "a finding below says the run is too small to answer its question"},
            {"trace_rays", "rays", "rays in the trace (`summary.rays`)"},
            {"rays_needed", "rays", "the largest trace size the findings ask for; `null` when none names one"},
            {"findings", "list", "each with `kind` (`ray_buffer_not_filled`: treelets on and the buffer's `max_occupancy` under half its `capacity_rays`, or 90% of picks drain picks; `drain_dominates`: contexts idle at the trace's end over 10% of context cycles, `tail_fraction`; `sample_too_short`: one of `sampling.caveats`), `rays_needed` (the trace size that would do; `null` when more rays would not help, e.g. a buffer kept empty by admission) and `text`"},
        }};
    return block;
}

RTSIM_REGISTER_STAT_BLOCK(study_size_stats)

ReportBlock study_size_report() {
    ReportBlock b;
    b.name = "study size";
    b.order = 65;  // after the roofline, before the verdict (whose text repeats the findings)
    b.add = [](json& stats, const ReportInputs& in) {
        json size = study_size(in.config, stats);
        json texts = json::array();
        for (const json& f : size["findings"]) texts.push_back(f["text"]);
        stats["summary"]["study_warnings"] = texts;
        stats["study_size"] = std::move(size);
    };
    b.keys = {{"study_size", study_size_stats}};
    return b;
}

}  // namespace

RTSIM_REGISTER_REPORT_BLOCK(study_size_report())

}  // namespace rtsim
