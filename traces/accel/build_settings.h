#pragma once
// Builder settings as data (docs/accel.md, "Builder settings"): every builder's documented Config
// struct lists its fields once in a visit() (name, value, unit, one-line doc, range), as the
// simulator's config tree does, and the visitors here read overrides ("bins=32"), write the
// resolved settings into the manifest and dump the schema for Python and the docs. So SAH bins
// and costs, leaf sizes, the grid's density, SBVH's alpha, the kd-tree's empty-space bonus and the
// octree's depth reach the command line (`rtsim trace --build-set key=value`), the manifest, the
// trace cache key and a sweep axis from one declaration each.
#include <cstdint>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

namespace rtsim {

/// What a Config's visit(V&) calls; implemented by the readers and writers below.
class SettingsVisitor {
public:
    virtual ~SettingsVisitor() = default;
    virtual void field(const char* name, uint32_t& value, const char* unit, const char* doc, double lo, double hi) = 0;
    virtual void field(const char* name, uint64_t& value, const char* unit, const char* doc, double lo, double hi) = 0;
    virtual void field(const char* name, float& value, const char* unit, const char* doc, double lo, double hi) = 0;
    virtual void flag(const char* name, bool& value, const char* doc) = 0;
};

/// Visits the settings one (kind, builder) takes, in a fixed order.
using SettingsVisit = std::function<void(SettingsVisitor&)>;

/// {name: value} of every setting visited.
nlohmann::json settings_values(const SettingsVisit& visit);
/// {name: {type, default, unit, min, max, doc}} of every setting visited (values as they are now).
nlohmann::json settings_schema(const SettingsVisit& visit);
/// Applies {name: value} overrides (numbers, or strings holding a number or true/false, as the
/// command line gives them). Throws rtsim::Error naming `what`, the key and what it takes: an
/// unknown key (listing the known ones), a value of the wrong type or out of its range.
void apply_settings(const SettingsVisit& visit, const nlohmann::json& overrides, const std::string& what);
/// Parses "key=value" into overrides[key] = value (the value as JSON if it parses, else the text).
/// Throws rtsim::Error naming the text if it has no '=' or an empty key.
void parse_setting(const std::string& assignment, nlohmann::json* overrides);

}  // namespace rtsim
