#include "rtl_model/traversal/cycle_accounting.h"

#include <algorithm>
#include <string>

namespace rtsim {

std::string cycle_use_name(CycleUse use) {
    static const char* const kNames[] = {"issue", "dispatch",   "l1_hit", "l2",      "dram", "l1_mshr_full",
                                         "l2_mshr_full", "stack", "ray_buffer", "starved", "tail",
                                         "idle_lane"};
    const int i = int(use);
    if (i < int(CycleUse::pipe_first)) return kNames[i];
    return std::string("pipe_") + op_kind_name(OpKind(i - int(CycleUse::pipe_first)));
}

uint64_t CycleAccount::total() const {
    uint64_t sum = 0;
    for (uint64_t c : m_cycles) sum += c;
    return sum;
}

CycleAccount& CycleAccount::operator+=(const CycleAccount& o) {
    for (size_t i = 0; i < m_cycles.size(); ++i) m_cycles[i] += o.m_cycles[i];
    return *this;
}

nlohmann::json CycleAccount::to_json() const {
    nlohmann::json j = nlohmann::json::object();
    for (int i = 0; i < kCycleUseCount; ++i)
        if ((i < int(CycleUse::pipe_first) && CycleUse(i) != CycleUse::idle_lane) || m_cycles[size_t(i)]) j[cycle_use_name(CycleUse(i))] = m_cycles[size_t(i)];
    return j;
}

}  // namespace rtsim
