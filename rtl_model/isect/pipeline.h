#pragma once
// A fixed-function test pipeline (ray-box or ray-triangle): `width` tests per issue, one issue
// every `initiation_interval` cycles, results `latency` cycles after issue. The tests themselves
// are computed by the traversal stepper with the arithmetic of traces/isect; this block adds time.
//
// Private pipelines are used by one unit in time order (exact reservation). A shared pool of
// `shared_count` pipelines is a bandwidth calendar of shared_count issues per initiation interval,
// so units that run ahead within a quantum still contend correctly. At the detailed level
// (exact = true) the pool is a per-slot calendar instead: shared_count issues per initiation
// interval, each starting at its slot, granted in arrival order (units synchronise every cycle).
#include <cstdint>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>
#include <systemc>

#include "rtl_model/common/calendar.h"
#include "rtl_model/common/stats.h"
#include "rtl_model/common/usage_series.h"
#include "rtl_model/isect/pipeline_config.h"

namespace rtsim {

/// The stats every pipeline block writes (model.<kind>.<pipe>; the analytic level's too).
const StatBlock& pipeline_stats();

class Pipeline : public sc_core::sc_module, public PipeIf {
public:
    /// count: pipelines behind this block (1 when private, shared_count when shared).
    Pipeline(sc_core::sc_module_name name, const PipelineConfig& config, bool shared, bool exact = false);

    Cycle issue(Cycle time, uint32_t issues, uint32_t tests) override;

    uint64_t issues() const { return m_issues; }
    uint64_t tests() const { return m_tests; }
    uint32_t pipelines() const { return m_shared ? m_config.shared_count : 1; }
    bool shared() const { return m_shared; }
    /// Issues over time (capacity: pipelines() / initiation_interval per cycle).
    const UsageSeries& issue_use() const { return m_issue_use; }
    double issue_capacity() const { return double(pipelines()) / m_config.initiation_interval; }
    nlohmann::json stats_json(Cycle total_cycles) const;

private:
    PipelineConfig m_config;
    bool m_shared;
    InOrderResource m_private;
    std::unique_ptr<BandwidthCalendar> m_pool;
    std::unique_ptr<SlotCalendar> m_exact_pool;  ///< shared pool at the detailed level
    uint64_t m_issues = 0, m_tests = 0, m_wait_cycles = 0;
    UsageSeries m_issue_use;
};

}  // namespace rtsim
