#include "rtl_model/traversal/unit_kind.h"

#include <algorithm>
#include <map>

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
