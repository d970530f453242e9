// Is this run's level inside the band it was measured in, for this kind of design? (docs/fidelity.md,
// "Designs a level was measured outside its band on"). The analytic level is within 10% of
// `detailed` on the design grids it was measured on, but on some kinds of design it was measured
// well outside that band; a run of such a design says so in its summary, names the mechanism the
// level leaves out and the level that was within its band there, so an architect reads the figure
// as what it is. The kinds are the accuracy grids' (python/rtsim/specs/unit_models_grid.yaml and
// starved_grid.yaml); their measured errors are in docs/fidelity.md, generated from those runs.
#include <cstdio>
#include <string>

#include "rtl_model/common/stats.h"
#include "rtl_model/traversal/unit_kind.h"
#include "sim/report/report_block.h"

namespace rtsim {

using nlohmann::json;

namespace {

/// Rays per ray context below which the fill and the drain are a large part of the run: the
/// starved grid's fill-limited points hold 0.3-6 rays per context, its other points 48.
constexpr double kFewRaysPerContext = 8;

json finding(const char* kind, const std::string& why, const char* section) {
    return {{"kind", kind},
            {"text", "analytic: " + why + "; the level was measured outside its 10% band on such designs "
                     "(docs/fidelity.md, \"" + section + "\"), approx within it: use approx or detailed for figures"},
            {"section", section}};
}

json fidelity_band(const SimConfig& c, const json& stats, const std::string& structure) {
    json findings = json::array();
    if (c.fidelity == Fidelity::analytic) {
        const bool lock_step = c.traversal.kind().needs.lock_step;
        const json& summary = stats.value("summary", json::object());
        const json& r = summary.value("rays", json(nullptr));
        const double rays = r.is_number() ? r.get<double>() : 0.0;
        const double contexts = double(c.traversal.units) * c.traversal.contexts();
        const double per_context = contexts > 0 ? rays / contexts : 0.0;
        if (c.treelets.enabled && !lock_step)
            findings.push_back(finding("treelets_on_contexts",
                                       "MIMD units with treelet scheduling: a treelet's contexts become ready together "
                                       "and convoy at the scheduler, which the closed form models only by their mean "
                                       "(it is fast on Sponza, up to 12%)",
                                       "What is left with treelets"));
        if (c.treelets.enabled && lock_step)
            findings.push_back(finding("treelets_on_groups",
                                       "lock-step units with treelet queues: a warp step waits for the slowest of its "
                                       "lines drawn independently, while a treelet warp's lanes read one small treelet's "
                                       "(it can be slow where the DRAM is fast)",
                                       "What is left with treelets"));
        const bool packets = c.traversal.model == "packet";
        if ((packets && (structure == "bih" || structure == "grid")) || structure == "grid")
            findings.push_back(finding("cell_structure",
                                       packets ? "packets on the " + structure +
                                                     ": a packet whose steps serve one or two of its rays walks the "
                                                     "same cells ray after ray, so its lines hit the L1 more than the "
                                                     "analysis's context-by-context reuse says (it is slow)"
                                               : std::string("the grid: its 3D-DDA walks were measured up to 18% fast"),
                                       "Packets on cell structures"));
        const json& frames = summary.value("frames", json(nullptr));
        if (c.build_unit.overlap && frames.is_number() && frames.get<double>() > 1)
            findings.push_back(finding("build_overlap",
                                       "builds beside the previous frame's rays (build_unit.overlap): the closed form "
                                       "gives a build the traversal's loaded latency and bounds the two by the DRAM's "
                                       "bandwidth, but leaves out how much the build slows the traversal (it is fast, "
                                       "20% on the exploding hairball's rebuilds)",
                                       "Frames at the analytic level"));
        // Contexts' and warps' rounds both wait for their slow lines (rounds as time), but a
        // warp's drain is priced from where its lines were served at the default caches.
        if (lock_step && rays > 0 && per_context < kFewRaysPerContext) {
            char buf[32];
            std::snprintf(buf, sizeof buf, "%.1f", per_context);
            const std::string why =
                std::string(buf) + " rays per ray context (" + std::to_string(uint64_t(rays)) + " rays, " +
                std::to_string(uint64_t(contexts)) + " contexts): the fill and the drain are much of the run; " +
                "the phases are priced and the groups wait for their lines, but a drain group's step is priced "
                "from where its lines were served at the default caches (measured from 15% fast to 20% slow)";
            findings.push_back(finding("few_rays_per_context", why, "Where designs starve or fill slowly"));
        }
    }
    json texts = json::array();
    for (const json& f : findings) texts.push_back(f["text"]);
    return {{"level", kFidelityChoices.name(c.fidelity)}, {"outside", !findings.empty()}, {"findings", findings}, {"texts", texts}};
}

const StatBlock& fidelity_band_stats() {
    static const StatBlock block{
        "fidelity_band",
        {
            {"level", "", "the run's fidelity level"},
            {"outside", "bool", "the design is of a kind the level was measured outside its band on (docs/fidelity.md)"},
            {"findings", "list", "each with `kind` (`treelets_on_contexts`: analytic with treelet scheduling on MIMD units; `treelets_on_groups`: analytic with treelet queues on lock-step units; `cell_structure`: analytic on the grid, or packets on the BIH; `few_rays_per_context`: analytic on lock-step units with fewer than 8 rays per ray context; `build_overlap`: analytic on an animated trace with `build_unit.overlap`), `text` and `section` (the docs/fidelity.md section with the measured errors)"},
        }};
    return block;
}

RTSIM_REGISTER_STAT_BLOCK(fidelity_band_stats)

ReportBlock fidelity_band_report() {
    ReportBlock b;
    b.name = "fidelity band";
    b.order = 66;  // after the study size, before the verdict
    b.add = [](json& stats, const ReportInputs& in) {
        json band = fidelity_band(in.config, stats, in.structure_kind);
        stats["summary"]["fidelity_warnings"] = band["texts"];
        band.erase("texts");
        stats["fidelity_band"] = std::move(band);
    };
    b.keys = {{"fidelity_band", fidelity_band_stats}};
    return b;
}

}  // namespace

RTSIM_REGISTER_REPORT_BLOCK(fidelity_band_report())

}  // namespace rtsim
