#include "sim/analytic/profile.h"

#include "sim/analytic/reuse.h"
#include "traces/common/error.h"

namespace rtsim {

using nlohmann::json;

namespace {

json hist_json(const JointHistogram& h) {
    json a = json::array();
    for (const auto& [k, n] : h.cells) a.push_back({k, n});
    return a;
}

JointHistogram hist_from(const json& a) {
    JointHistogram h;
    for (const json& e : a) h.cells[e.at(0).get<uint32_t>()] = e.at(1).get<double>();
    return h;
}

json map_json(const std::map<uint64_t, double>& m) {
    json a = json::array();
    for (const auto& [k, n] : m) a.push_back({k, n});
    return a;
}

std::map<uint64_t, double> map_from(const json& a) {
    std::map<uint64_t, double> m;
    for (const json& e : a) m[e.at(0).get<uint64_t>()] = e.at(1).get<double>();
    return m;
}

template <class Array>
json array_json(const Array& a) {
    return json(std::vector<double>(a.begin(), a.end()));
}

template <class Array>
void array_from(const json& j, Array* a) {
    const std::vector<double> v = j.get<std::vector<double>>();
    require(v.size() == a->size(), "analytic profile: array of " + std::to_string(v.size()) + " values, expected " +
                                       std::to_string(a->size()));
    std::copy(v.begin(), v.end(), a->begin());
}

json phases_json(const std::vector<PhaseWindow>& phases) {
    json a = json::array();
    for (const PhaseWindow& w : phases)
        a.push_back({{"rounds", w.rounds}, {"steps", w.steps}, {"contexts", w.contexts}, {"reads", hist_json(w.reads)},
                     {"critical", hist_json(w.critical)}});
    return a;
}

std::vector<PhaseWindow> phases_from(const json& a) {
    std::vector<PhaseWindow> phases;
    for (const json& e : a)
        phases.push_back({e.at("rounds").get<double>(), e.at("steps").get<double>(), e.at("contexts").get<double>(),
                          hist_from(e.at("reads")), hist_from(e.at("critical"))});
    return phases;
}

}  // namespace

double JointHistogram::total() const {
    double t = 0;
    for (const auto& [k, n] : cells) t += n;
    return t;
}

AnalyticProfile::AnalyticProfile()
    : op_sizes(kOpKindCount),
      unit_events(DistanceBins::kBins, 0.0),
      unit_censored(DistanceBins::kBins, 0.0),
      global_events(DistanceBins::kBins, 0.0),
      global_censored(DistanceBins::kBins, 0.0) {}

double AnalyticProfile::plan_step_work(const std::array<double, kWorkFieldCount>& sums) {
    double n = 0;
    for (size_t f = 0; f < sums.size(); ++f)
        if (kWorkFields[f].plan_step) n += sums[f];
    return n;
}

json AnalyticProfile::to_json() const {
    json ops = json::array();
    for (const auto& sizes : op_sizes) {
        json o = json::array();
        for (const auto& [n, f] : sizes) o.push_back({n, f});
        ops.push_back(o);
    }
    std::vector<int> kinds;
    for (OpKind k : op_kinds) kinds.push_back(int(k));
    json reads_j = json::array();
    for (const JointHistogram& h : reads) reads_j.push_back(hist_json(h));
    return {{"schema", "rtsim-analytic-profile/1"},
            {"key", key},
            {"accel_kind", accel_kind},
            {"op_kinds", kinds},
            {"rays", rays},
            {"work", array_json(work)},
            {"longest_ray_steps", longest_ray_steps},
            {"longest_ray_tests", longest_ray_tests},
            {"sample_rays", sample_rays},
            {"whole_trace", whole_trace},
            {"sample_work", array_json(sample_work)},
            {"sample_plan_steps", sample_plan_steps},
            {"plan_steps_per", {plan_steps_per[0], plan_steps_per[1]}},
            {"op_sizes", ops},
            {"reads", reads_j},
            {"read_bytes", array_json(read_bytes)},
            {"step_critical", hist_json(step_critical)},
            {"ray_critical", hist_json(ray_critical)},
            {"merge_l1", map_json(merge_l1)},
            {"merge_l2", map_json(merge_l2)},
            {"writes", array_json(writes)},
            {"write_bytes", array_json(write_bytes)},
            {"spill_writes", spill_writes},
            {"spill_reads", spill_reads},
            {"unit_events", unit_events},
            {"unit_censored", unit_censored},
            {"global_events", global_events},
            {"global_censored", global_censored},
            {"validation", validation},
            {"workload", workload},
            {"stepped_rays", stepped_rays},
            {"analysis_seconds", analysis_seconds},
            {"phases", phases_json(phases)},
            {"phase_machine", {phase_units, phase_contexts}},
            {"frame_samples", [&] {
                 json a = json::array();
                 for (const FrameSample& f : frame_samples) a.push_back({{"frame", f.frame}, {"reads", hist_json(f.reads)}});
                 return a;
             }()},
            {"group", has_group ? group.to_json() : json(nullptr)},
            {"treelets", {{"takes", treelet_takes}, {"parks", treelet_parks}, {"overflows", treelet_overflows}}}};
}

AnalyticProfile AnalyticProfile::from_json(const json& j) {
    require(j.value("schema", "") == "rtsim-analytic-profile/1", "analytic profile: unknown schema");
    AnalyticProfile p;
    p.key = j.at("key");
    p.accel_kind = j.at("accel_kind");
    for (int k : j.at("op_kinds").get<std::vector<int>>()) p.op_kinds.push_back(OpKind(k));
    p.rays = j.at("rays");
    array_from(j.at("work"), &p.work);
    p.longest_ray_steps = j.at("longest_ray_steps");
    p.longest_ray_tests = j.at("longest_ray_tests");
    p.sample_rays = j.at("sample_rays");
    p.whole_trace = j.at("whole_trace");
    array_from(j.at("sample_work"), &p.sample_work);
    p.sample_plan_steps = j.at("sample_plan_steps");
    p.plan_steps_per[0] = j.at("plan_steps_per").at(0);
    p.plan_steps_per[1] = j.at("plan_steps_per").at(1);
    const json& ops = j.at("op_sizes");
    for (size_t k = 0; k < ops.size() && k < p.op_sizes.size(); ++k)
        for (const json& e : ops[k]) p.op_sizes[k][e.at(0).get<uint32_t>()] = e.at(1).get<double>();
    const json& reads = j.at("reads");
    require(reads.size() == p.reads.size(), "analytic profile: reads per data kind");
    for (size_t k = 0; k < reads.size(); ++k) p.reads[k] = hist_from(reads[k]);
    array_from(j.at("read_bytes"), &p.read_bytes);
    p.step_critical = hist_from(j.at("step_critical"));
    p.ray_critical = hist_from(j.at("ray_critical"));
    p.merge_l1 = map_from(j.at("merge_l1"));
    p.merge_l2 = map_from(j.at("merge_l2"));
    array_from(j.at("writes"), &p.writes);
    array_from(j.at("write_bytes"), &p.write_bytes);
    p.spill_writes = j.at("spill_writes");
    p.spill_reads = j.at("spill_reads");
    p.unit_events = j.at("unit_events").get<std::vector<double>>();
    p.unit_censored = j.at("unit_censored").get<std::vector<double>>();
    p.global_events = j.at("global_events").get<std::vector<double>>();
    p.global_censored = j.at("global_censored").get<std::vector<double>>();
    p.validation = j.at("validation");
    p.workload = j.at("workload");
    p.stepped_rays = j.at("stepped_rays");
    p.analysis_seconds = j.at("analysis_seconds");
    p.phases = phases_from(j.at("phases"));
    p.phase_units = j.at("phase_machine").at(0).get<uint32_t>();
    p.phase_contexts = j.at("phase_machine").at(1).get<uint32_t>();
    for (const json& f : j.at("frame_samples"))
        p.frame_samples.push_back({f.at("frame").get<uint32_t>(), hist_from(f.at("reads"))});
    if (j.contains("treelets")) {
        const json& t = j.at("treelets");
        p.treelet_takes = t.at("takes"), p.treelet_parks = t.at("parks"), p.treelet_overflows = t.at("overflows");
    }
    if (j.contains("group") && !j.at("group").is_null()) {
        p.has_group = true;
        p.group = GroupProfile::from_json(j.at("group"));
    }
    return p;
}

}  // namespace rtsim
