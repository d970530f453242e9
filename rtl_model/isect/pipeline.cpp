#include "rtl_model/isect/pipeline.h"

namespace rtsim {

Pipeline::Pipeline(sc_core::sc_module_name name, const PipelineConfig& config, bool shared, bool exact)
    : sc_core::sc_module(name), m_config(config), m_shared(shared) {
    // shared_count issues per initiation interval: counted per window of 16 intervals (approx) or
    // per interval exactly (detailed).
    if (shared && exact) m_exact_pool = std::make_unique<SlotCalendar>(config.shared_count, config.initiation_interval);
    else if (shared) m_pool = std::make_unique<BandwidthCalendar>(16ull * config.shared_count, 16 * config.initiation_interval);
}

Cycle Pipeline::issue(Cycle time, uint32_t issues, uint32_t tests) {
    if (issues == 0) return time;
    m_issues += issues;
    m_tests += tests;
    const Cycle ii = m_config.initiation_interval;
    Cycle first, last;
    if (!m_shared) {
        first = m_private.reserve(time, issues * ii);
        last = first + (issues - 1) * ii;
    } else {
        // Each issue takes one pipeline slot of one initiation interval somewhere in the pool.
        auto slot = [&](Cycle t) { return m_exact_pool ? m_exact_pool->reserve(t, 1) : m_pool->reserve(t, 1); };
        first = last = slot(time);
        for (uint32_t i = 1; i < issues; ++i) last = slot(last);
    }
    m_wait_cycles += first - time;
    m_issue_use.add(first, issues);
    return last + m_config.latency;
}

const StatBlock& pipeline_stats() {
    static const StatBlock block{
        "model.<kind>.<pipe>",
        {
            {"issues", "issues", "issues into the pipeline(s): `ceil(tests / width)` per operation"},
            {"tests", "tests", "tests of the block's kind: ray-box (one per child of each node visited), ray-triangle (one per leaf triangle), alpha, transform, cell or plane"},
            {"pipelines", "pipelines", "pipelines behind this block: 1 (private) or `shared_count`"},
            {"utilization", "fraction", "`issues / (summary.cycles * pipelines / initiation_interval)`: issue slots used"},
            {"avg_wait_cycles", "cycles", "mean cycles an issue waited for a free slot (contention); `null` at analytic", true},
        }};
    return block;
}

nlohmann::json Pipeline::stats_json(Cycle total_cycles) const {
    double capacity = double(total_cycles) * pipelines() / double(m_config.initiation_interval);
    nlohmann::json j;
    StatsWriter(pipeline_stats(), j)
        .set("issues", m_issues)
        .set("tests", m_tests)
        .set("pipelines", pipelines())
        .set("utilization", capacity > 0 ? double(m_issues) / capacity : 0.0)
        .set("avg_wait_cycles", m_issues ? double(m_wait_cycles) / double(m_issues) : 0.0)
        .done();
    return j;
}

RTSIM_REGISTER_STAT_BLOCK(pipeline_stats)

}  // namespace rtsim
