#include "sim/harness/hit_checker.h"

#include <cstring>
#include <sstream>

namespace rtsim {

namespace {
constexpr size_t kExamples = 20;
uint32_t bits(float f) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
}
}  // namespace

std::string compare_with_reference(const RayResult& r, const HitRecord& h, const WorkRecord& w, bool* hit_differs) {
    *hit_differs = r.hit.prim != h.prim || (h.prim >= 0 && bits(r.hit.t) != bits(h.t));
    const WorkCounts m = r.work.traced();  // a trace's work has no mailbox and no restarts
    const WorkCounts ref = w.counts();
    if (!*hit_differs && m == ref) return std::string();  // every ray comes here: no text unless needed
    std::ostringstream out;
    if (*hit_differs)
        out << "hit: model prim " << r.hit.prim << " t " << r.hit.t << ", reference prim " << h.prim << " t " << h.t;
    if (m != ref) {
        out << (*hit_differs ? "; " : "") << "work (model/reference):";
        for (const WorkFieldInfo& f : kWorkFields)
            if (m.*f.member != ref.*f.member) out << " " << f.name << " " << m.*f.member << "/" << ref.*f.member;
    }
    return out.str();
}

HitChecker::HitChecker(sc_core::sc_module_name name, ReferenceSource& reference, uint64_t total, Progress progress)
    : sc_core::sc_module(name), m_reference(reference), m_total(total), m_progress(std::move(progress)) {}

void HitChecker::ray_done(const RayResult& r) {
    if (m_reordered_anyhit && r.mode == TraversalMode::any_hit) return occlusion_done(r);
    check(r, m_reference.hit(r.id), m_reference.work(r.id));
}

void HitChecker::packet_done(const RayResult* results, const Ray* rays, const TraversalMode* modes, uint32_t n) {
    if (!m_packet_reference) return RaySinkIf::packet_done(results, rays, modes, n);
    std::vector<Hit> hits(n);
    std::vector<WorkCounts> work(n);
    m_packet_reference(rays, modes, n, hits.data(), work.data());
    for (uint32_t i = 0; i < n; ++i) {
        HitRecord want = m_reference.hit(results[i].id);
        if (m_reordered_anyhit && modes[i] == TraversalMode::any_hit) count_reordered(results[i]);
        // An any-hit ray that agrees with the trace on occlusion must have the packet loop's hit
        // (the packet loop walks in the run's any-hit order too).
        if (modes[i] == TraversalMode::any_hit && (want.prim >= 0) == hits[i].valid()) {
            want.prim = hits[i].prim;
            want.t = hits[i].t;
        }
        check(results[i], want, WorkRecord::of(work[i]));
    }
}

void HitChecker::occlusion_done(const RayResult& r) {
    HitRecord want = m_reference.hit(r.id);
    count_reordered(r);
    if ((want.prim >= 0) == r.hit.valid()) {
        want.prim = r.hit.prim;
        want.t = r.hit.t;
    }
    check(r, want, WorkRecord::of(r.work.traced()));
}

void HitChecker::count_reordered(const RayResult& r) {
    // The same ray's work in the trace's order (nearest first) against its own: what the
    // order changes (validation.reordered_anyhit).
    m_reordered_reference.add(m_reference.work(r.id).counts());
    m_reordered_own.add(r.work);
    ++m_reordered;
}

void HitChecker::check(const RayResult& r, const HitRecord& ref_hit, const WorkRecord& ref_work) {
    bool hit_differs = false;
    std::string diff = compare_with_reference(r, ref_hit, ref_work, &hit_differs);
    if (!diff.empty()) {
        if (hit_differs) ++m_hit_mismatches;
        else ++m_work_mismatches;
        if (m_examples.size() < kExamples) m_examples.push_back({{"ray", r.id}, {"difference", diff}});
    }
    m_reference.checked(r.id);
    m_latency.add(r.end - r.start);
    m_work.add(r.work);
    if (on_ray) on_ray(r);
    ++m_checked;
    if (m_progress && (m_checked % 4096 == 0 || m_checked == m_total)) m_progress(m_checked, m_total);
}

nlohmann::json HitChecker::to_json() const {
    nlohmann::json j = {{"rays_checked", m_checked},
                        {"rays_expected", m_total},
                        {"hit_mismatches", m_hit_mismatches},
                        {"work_mismatches", m_work_mismatches},
                        {"first_mismatches", m_examples}};
    if (m_reordered) {
        const double n = double(m_reordered);
        auto per_ray = [n](const WorkTotals& w) {
            return nlohmann::json{{"steps", double(w[WorkField::steps]) / n},
                                  {"box_tests", double(w[WorkField::box_tests]) / n},
                                  {"tri_tests", double(w[WorkField::tri_tests]) / n}};
        };
        j["reordered_anyhit"] = {{"rays", m_reordered}, {"own", per_ray(m_reordered_own)},
                                 {"trace_order", per_ray(m_reordered_reference)}};
    }
    return j;
}

const StatBlock& validation_stats() {
    static const StatBlock block{
        "validation",
        {
            {"rays_checked", "rays", "rays the model finished and the checker compared"},
            {"rays_expected", "rays", "rays in the trace, or the simulated rays of a sampled run (a run that finishes fewer is an error, exit 2)"},
            {"hit_mismatches", "rays", "hit differs: primitive id, or the bit pattern of t for a hit"},
            {"work_mismatches", "rays", "hit equal, work differs: any field of the ray's work counts"},
            {"first_mismatches", "list", "up to 20 `{ray, difference}`: the ray index and the fields that differ, model/reference"},
            {"reordered_anyhit", "", "only with `traversal.anyhit_order` other than `nearest` (the levels that step every ray: functional, approx, detailed, and analytic with `analytic.caches=functional`): `rays` (the any-hit rays walked in that order, their occlusion checked), and per such ray `own` and `trace_order` `{steps, box_tests, tri_tests}`: their work in the run's order and in the trace's (nearest first)", false, true},
            {"scope", "", "analytic level only: which rays were checked (the analysis's sampled rays)", false, true},
            {"shaded_rays", "rays", "only with `shading.enabled`: rays the shading block shaded (every ray, once)", false, true},
            {"texel_mismatches", "rays", "only with `shading.enabled`: rays whose texel addresses differ from the reference tracer's (0 allowed, else exit 3)", false, true},
            {"first_texel_mismatch", "", "only with texel mismatches: the first such ray", false, true},
            {"order_violations", "rays", "only with `shading.enabled`: rays started before their parent was shaded, or shaded twice (0 allowed, else exit 3)", false, true},
        }};
    return block;
}

RTSIM_REGISTER_STAT_BLOCK(validation_stats)

}  // namespace rtsim
