#include "sim/report/roofline.h"

#include "rtl_model/isect/pipeline.h"
#include "rtl_model/traversal/traversal_unit.h"

namespace rtsim {

using nlohmann::json;

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
    for (const json& u : model.value("units", json::object())) steps += StatsReader(unit_stats(), u)["steps"].get<double>();
    if (steps > 0) ceilings["scheduler"] = double(c.traversal.units) * hz / c.traversal.issue_cycles / (steps / rays);
    std::string bound;
    double lowest = 0;
    for (auto it = ceilings.begin(); it != ceilings.end(); ++it)
        if (bound.empty() || it.value().get<double>() < lowest) {
            lowest = it.value().get<double>();
            bound = it.key();
        }
    return {{"dram_bytes_per_ray", bytes},
            {"rays_per_second", summary.value("rays_per_second", json(nullptr))},
            {"peak_dram_bytes_per_second", double(c.dram.bytes_per_cycle) * c.dram.channels * hz},
            {"ceilings", ceilings},
            {"bound", bound},
            {"bound_rays_per_second", bound.empty() ? json(nullptr) : json(lowest)}};
}

const StatBlock& roofline_stats() {
    static const StatBlock block{
        "roofline",
        {
            {"rays_per_second", "rays/s", "achieved (`summary.rays_per_second`)"},
            {"ceilings", "rays/s", "`{resource: rays/s}` what each resource alone allows: `dram` = peak DRAM bytes/s over `dram_bytes_per_ray`, `box`, `triangle`, ... = pipeline issue slots/s over issues per ray, `scheduler` = units x clock / (steps per ray x `issue_cycles`)"},
            {"bound", "", "the lowest ceiling's name"},
            {"bound_rays_per_second", "rays/s", "the lowest ceiling; the run can never be faster (tested)"},
            {"dram_bytes_per_ray", "bytes/ray", "as `summary.dram_bytes_per_ray`"},
            {"peak_dram_bytes_per_second", "B/s", "`channels x bytes_per_cycle x clock`"},
        }};
    return block;
}

}  // namespace rtsim
