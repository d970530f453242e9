#include "sim/report/dram_latency_calibration.h"

#include <algorithm>
#include <cmath>

namespace rtsim {

uint32_t DramLatencyCalibration::added_cycles() const {
    // The bank wait is queueing, not charged (dram_latency_calibration.h).
    return measured ? uint32_t(std::lround(std::max(0.0, row_cycles))) : 0u;
}

SimConfig DramLatencyCalibration::apply(SimConfig config) const {
    config.dram.latency += added_cycles();
    return config;
}

nlohmann::json DramLatencyCalibration::to_json() const {
    if (!measured) return nullptr;
    return {{"row_cycles", row_cycles}, {"bank_wait_cycles", bank_wait}, {"added_cycles", added_cycles()}};
}

DramLatencyCalibration calibrate_dram_latency(const SimConfig& c, const nlohmann::json& dram) {
    DramLatencyCalibration k;
    if (c.dram.model != DramModel::banks || !dram.is_object() || !dram.contains("row_conflicts")) return k;
    const double hits = dram.value("row_hits", 0.0), misses = dram.value("row_misses", 0.0),
                 conflicts = dram.value("row_conflicts", 0.0);
    const double all = hits + misses + conflicts;
    if (all <= 0) return k;
    k.measured = true;
    k.row_cycles = (conflicts * c.dram.t_rp - hits * c.dram.t_rcd) / all;
    const nlohmann::json& wait = dram.contains("avg_queue_cycles") ? dram["avg_queue_cycles"] : nlohmann::json(0.0);
    k.bank_wait = wait.is_number() ? wait.get<double>() : 0.0;
    return k;
}

}  // namespace rtsim
