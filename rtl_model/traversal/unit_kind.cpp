#include "rtl_model/traversal/unit_kind.h"

#include <algorithm>
#include <map>

#include "rtl_model/common/round_windows.h"
#include "traces/common/error.h"

namespace rtsim {

namespace {

/// Ordered by name: the config tree, the schema and the docs list kinds in a stable order
/// whatever the order of static initialisation.
std::map<std::string, UnitKind>& registry() {
    static std::map<std::string, UnitKind> kinds;
    return kinds;
}

}  // namespace

bool register_unit_kind(UnitKind kind) {
    require(!kind.name.empty() && kind.make_unit != nullptr, "unit kinds: a kind needs a name and a factory");
    const std::string name = kind.name;
    require(registry().emplace(name, std::move(kind)).second, "unit kinds: '" + name + "' is registered twice");
    return true;
}

std::vector<const UnitKind*> unit_kinds() {
    std::vector<const UnitKind*> out;
    for (const auto& [name, kind] : registry()) out.push_back(&kind);
    return out;
}

std::string unit_kind_names() {
    std::string s;
    for (const auto& [name, kind] : registry()) s += (s.empty() ? "" : ", ") + name;
    return s;
}

const UnitKind& unit_kind(const std::string& name) {
    auto it = registry().find(name);
    require(it != registry().end(),
            "config: 'traversal.model' = '" + name + "' is not one of: " + unit_kind_names());
    return it->second;
}

void GroupWindow::end_round(std::vector<GroupWindow>& windows, double* window_rounds) {
    end_window_round(windows, window_rounds, kMaxWindows, [](GroupWindow& into, const GroupWindow& other) {
        into.rounds += other.rounds, into.group_steps += other.group_steps, into.active_lanes += other.active_lanes;
        into.groups += other.groups;
        for (size_t i = 0; i < into.served.size(); ++i) into.served[i] += other.served[i];
    });
}

GroupProfile& GroupProfile::operator+=(const GroupProfile& o) {
    if (rays == 0) phases = o.phases;
    else phases.clear();  // windows of two steppings do not add up to one run's
    rays += o.rays, scheduler_steps += o.scheduler_steps, group_steps += o.group_steps, buffer_steps += o.buffer_steps;
    lane_slots += o.lane_slots, active_lanes += o.active_lanes, occupied_lanes += o.occupied_lanes;
    lane_requests += o.lane_requests, requests += o.requests;
    for (size_t i = 0; i < work.size(); ++i) work[i] += o.work[i], single_work[i] += o.single_work[i];
    for (size_t i = 0; i < kind_steps.size(); ++i) kind_steps[i] += o.kind_steps[i];
    return *this;
}

nlohmann::json GroupProfile::to_json() const {
    return {{"rays", rays},
            {"scheduler_steps", scheduler_steps},
            {"group_steps", group_steps},
            {"buffer_steps", buffer_steps},
            {"lane_slots", lane_slots},
            {"active_lanes", active_lanes},
            {"occupied_lanes", occupied_lanes},
            {"lane_requests", lane_requests},
            {"requests", requests},
            {"work", work},
            {"single_work", single_work},
            {"kind_steps", kind_steps},
            {"phases", [&] {
                 nlohmann::json a = nlohmann::json::array();
                 for (const GroupWindow& w : phases) a.push_back({w.rounds, w.group_steps, w.active_lanes, w.groups, w.served});
                 return a;
             }()}};
}

GroupProfile GroupProfile::from_json(const nlohmann::json& j) {
    GroupProfile g;
    g.rays = j.at("rays"), g.scheduler_steps = j.at("scheduler_steps"), g.group_steps = j.at("group_steps");
    g.buffer_steps = j.at("buffer_steps");
    g.lane_slots = j.at("lane_slots"), g.active_lanes = j.at("active_lanes"), g.occupied_lanes = j.at("occupied_lanes");
    g.lane_requests = j.at("lane_requests"), g.requests = j.at("requests");
    g.work = j.at("work").get<std::array<double, kWorkFieldCount>>();
    g.single_work = j.at("single_work").get<std::array<double, kWorkFieldCount>>();
    g.kind_steps = j.at("kind_steps").get<std::array<double, kOpKindCount>>();
    for (const nlohmann::json& w : j.at("phases"))
        g.phases.push_back({w.at(0).get<double>(), w.at(1).get<double>(), w.at(2).get<double>(), w.at(3).get<double>(),
                            w.at(4).get<std::array<double, 3>>()});
    return g;
}

UnitSections::UnitSections(const UnitSections& other) { *this = other; }

UnitSections& UnitSections::operator=(const UnitSections& other) {
    if (this == &other) return *this;
    m_sections.clear();
    for (const auto& [name, section] : other.m_sections) m_sections.emplace_back(name, section->clone());
    return *this;
}

ConfigSection& UnitSections::get(const std::string& kind) const {
    for (auto& [name, section] : m_sections)
        if (name == kind) return *section;
    const UnitKind& k = unit_kind(kind);
    require(k.make_section != nullptr, "config: traversal.model '" + kind + "' has no section of its own");
    m_sections.emplace_back(kind, k.make_section());
    return *m_sections.back().second;
}

}  // namespace rtsim
