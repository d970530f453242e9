#include "sim/config/config.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <vector>

#include "traces/common/error.h"

namespace rtsim {

using nlohmann::json;

namespace {

std::string join_path(const std::string& prefix, const char* name) {
    return prefix.empty() ? std::string(name) : prefix + "." + name;
}

std::string format_number(double x) {
    // Whole numbers in full (2147483648, not 2.14748e+09, which reads as inside [0, 2.14748e+09]).
    if (std::isfinite(x) && std::trunc(x) == x && std::fabs(x) < 1e18) return std::to_string(int64_t(x));
    std::ostringstream out;
    out << std::setprecision(10) << x;
    return out.str();
}

/// What every visitor of the tree does with choices: an enum's Choices, a string among names
/// (traversal.model, whose names are the registered unit kinds) and an erased section's index
/// (rtl_model/common/config_section.h) all reach the visitor's one choice_names().
template <class Derived>
class ChoiceVisits {
public:
    template <class E, size_t N>
    void choice(const char* name, E& value, const Choices<E, N>& choices, const char* doc) {
        size_t index = static_cast<size_t>(value);
        self().choice_names(name, index, std::vector<const char*>(choices.names.begin(), choices.names.end()), doc);
        value = static_cast<E>(index);
    }
    void choice_of(const char* name, std::string& value, const std::vector<const char*>& names, const char* doc) {
        size_t index = 0;
        while (index < names.size() && value != names[index]) ++index;
        self().choice_names(name, index, names, doc);
        if (index < names.size()) value = names[index];
    }

private:
    Derived& self() { return static_cast<Derived&>(*this); }
};

/// Keys that moved into a unit kind's own section (traversal.<kind>): an old spec's key is
/// refused with where it went.
std::string moved_to(const std::string& key) {
    static const std::pair<const char*, const char*> kMoved[] = {
        {"traversal.lanes", "traversal.simt.lanes (warps) or traversal.packet.lanes (packets)"},
        {"traversal.simt_policy", "traversal.simt.policy"},
        {"traversal.simt_refill", "traversal.simt.refill"},
        {"traversal.packet_split_below", "traversal.packet.split_below"},
    };
    for (const auto& [from, to] : kMoved)
        if (key == from) return std::string(": it moved to ") + to;
    return "";
}

/// Reads fields from a JSON object; every key of the object must be visited (else: unknown).
class JsonReader : public ChoiceVisits<JsonReader> {
public:
    JsonReader(const json& j, std::string prefix) : m_json(j), m_prefix(std::move(prefix)) {
        require(j.is_object(), "config: '" + (m_prefix.empty() ? std::string("(root)") : m_prefix) + "' must be an object");
    }

    template <class T>
    void field(const char* name, T& value, const char*, const char*, double, double) {
        const json* j = take(name);
        if (!j) return;
        require(j->is_number() && !j->is_boolean(), "config: '" + join_path(m_prefix, name) + "' must be a number");
        if constexpr (std::is_integral_v<T>) {
            double d = j->get<double>();
            require(d >= 0 && std::floor(d) == d && d <= double(std::numeric_limits<T>::max()),
                    "config: '" + join_path(m_prefix, name) + "' must be a non-negative integer, got " + j->dump());
            value = T(d);
        } else {
            value = j->get<T>();
        }
    }
    void choice_names(const char* name, size_t& index, const std::vector<const char*>& names, const char*) {
        const json* j = take(name);
        if (!j) return;
        require(j->is_string(), "config: '" + join_path(m_prefix, name) + "' must be a string");
        const std::string text = j->get<std::string>();
        for (size_t i = 0; i < names.size(); ++i)
            if (text == names[i]) {
                index = i;
                return;
            }
        std::string list;
        for (const char* o : names) list += (list.empty() ? "" : ", ") + std::string(o);
        throw Error("config: '" + join_path(m_prefix, name) + "' = '" + text + "' is not one of: " + list);
    }
    void flag(const char* name, bool& value, const char*) {
        const json* j = take(name);
        if (!j) return;
        require(j->is_boolean(), "config: '" + join_path(m_prefix, name) + "' must be true or false");
        value = j->get<bool>();
    }
    template <class S>
    void section(const char* name, S& s) {
        const json* j = take(name);
        if (!j) return;
        JsonReader inner(*j, join_path(m_prefix, name));
        s.visit(inner);
        inner.finish();
    }
    /// Unknown keys are errors: a misspelt key must never be silently ignored.
    void finish() const {
        for (auto it = m_json.begin(); it != m_json.end(); ++it)
            if (std::find(m_seen.begin(), m_seen.end(), it.key()) == m_seen.end())
                throw Error("config: unknown key '" + join_path(m_prefix, it.key().c_str()) + "'" +
                            moved_to(join_path(m_prefix, it.key().c_str())) + known_keys());
    }

private:
    const json* take(const char* name) {
        m_seen.emplace_back(name);
        auto it = m_json.find(name);
        return it == m_json.end() ? nullptr : &*it;
    }
    std::string known_keys() const {
        std::string s = " (known keys here: ";
        for (size_t i = 0; i < m_seen.size(); ++i) s += (i ? ", " : "") + m_seen[i];
        return s + ")";
    }
    const json& m_json;
    std::string m_prefix;
    std::vector<std::string> m_seen;
};

class JsonWriter : public ChoiceVisits<JsonWriter> {
public:
    explicit JsonWriter(json& out) : m_out(out) { m_out = json::object(); }
    template <class T>
    void field(const char* name, T& value, const char*, const char*, double, double) { m_out[name] = value; }
    void choice_names(const char* name, size_t& index, const std::vector<const char*>& names, const char*) {
        m_out[name] = index < names.size() ? names[index] : "unknown";
    }
    void flag(const char* name, bool& value, const char*) { m_out[name] = value; }
    template <class S>
    void section(const char* name, S& s) {
        JsonWriter inner(m_out[name]);
        s.visit(inner);
    }

private:
    json& m_out;
};

class SchemaWriter : public ChoiceVisits<SchemaWriter> {
public:
    explicit SchemaWriter(json& out) : m_out(out) { m_out = json::object(); }
    template <class T>
    void field(const char* name, T& value, const char* unit, const char* doc, double lo, double hi) {
        add(name, {{"type", std::is_integral_v<T> ? "int" : "float"}, {"default", value}, {"unit", unit},
                   {"min", lo}, {"max", hi}, {"doc", doc}});
    }
    void choice_names(const char* name, size_t& index, const std::vector<const char*>& names, const char* doc) {
        add(name, {{"type", "choice"}, {"default", index < names.size() ? names[index] : "unknown"},
                   {"choices", std::vector<std::string>(names.begin(), names.end())}, {"doc", doc}});
    }
    void flag(const char* name, bool& value, const char* doc) {
        add(name, {{"type", "bool"}, {"default", value}, {"doc", doc}});
    }
    template <class S>
    void section(const char* name, S& s) {
        json sec = {{"type", "section"}};
        SchemaWriter inner(sec["fields"]);
        s.visit(inner);
        add(name, std::move(sec));
    }

private:
    /// Entries carry their declaration order ("index"): JSON objects are unordered.
    void add(const char* name, json entry) {
        entry["index"] = m_next++;
        m_out[name] = std::move(entry);
    }
    json& m_out;
    int m_next = 0;
};

class RangeValidator : public ChoiceVisits<RangeValidator> {
public:
    explicit RangeValidator(std::string prefix = "") : m_prefix(std::move(prefix)) {}
    template <class T>
    void field(const char* name, T& value, const char* unit, const char*, double lo, double hi) {
        double d = double(value);
        require(std::isfinite(d) && d >= lo && d <= hi,
                "config: '" + join_path(m_prefix, name) + "' = " + format_number(d) + " is out of range [" +
                    format_number(lo) + ", " + format_number(hi) + "] " + unit);
    }
    /// Choices are validated when read (JsonReader::choice_names); one set in code may be invalid.
    void choice_names(const char* name, size_t& index, const std::vector<const char*>& names, const char*) {
        std::string list;
        for (const char* o : names) list += (list.empty() ? "" : ", ") + std::string(o);
        require(index < names.size(), "config: '" + join_path(m_prefix, name) + "' holds an invalid value (one of: " +
                                          list + ")");
    }
    void flag(const char*, bool&, const char*) {}
    template <class S>
    void section(const char* name, S& s) {
        RangeValidator inner(join_path(m_prefix, name));
        s.visit(inner);
    }

private:
    std::string m_prefix;
};

}  // namespace

SimConfig config_from_json(const json& j, const SimConfig& base) {
    SimConfig c = base;
    JsonReader reader(j, "");
    c.visit(reader);
    reader.finish();
    return c;
}

void config_set(SimConfig& config, const std::string& assignment) {
    size_t eq = assignment.find('=');
    require(eq != std::string::npos && eq > 0, "config: --set expects key=value, got '" + assignment + "'");
    std::string path = assignment.substr(0, eq), text = assignment.substr(eq + 1);
    json value = json::parse(text, nullptr, false);
    if (value.is_discarded()) value = text;  // bare strings: --set box.sharing=shared
    // Build {"a": {"b": value}} and read it over the current config.
    json patch = value;
    std::vector<std::string> parts;
    for (size_t start = 0;;) {
        size_t dot = path.find('.', start);
        parts.push_back(path.substr(start, dot - start));
        if (dot == std::string::npos) break;
        start = dot + 1;
    }
    for (auto it = parts.rbegin(); it != parts.rend(); ++it) patch = json{{*it, patch}};
    try {
        config = config_from_json(patch, config);
    } catch (const Error& e) {
        // Name the whole assignment too: for "nonsense.key=1" the reader only sees 'nonsense'.
        throw Error(std::string(e.what()) + " (in '" + assignment + "')");
    }
}

json config_to_json(const SimConfig& config) {
    json out;
    SimConfig copy = config;
    JsonWriter writer(out);
    copy.visit(writer);
    return out;
}

namespace {

/// Finds one field by its dotted path.
class FieldFinder : public ChoiceVisits<FieldFinder> {
public:
    FieldFinder(const std::string& key, std::string prefix, ConfigField* out, bool* found)
        : m_key(key), m_prefix(std::move(prefix)), m_out(out), m_found(found) {}
    template <class T>
    void field(const char* name, T& value, const char*, const char*, double lo, double hi) {
        if (join_path(m_prefix, name) == m_key) *m_out = {json(value), lo, hi}, *m_found = true;
    }
    void choice_names(const char* name, size_t& index, const std::vector<const char*>& names, const char*) {
        if (join_path(m_prefix, name) == m_key)
            *m_out = {json(index < names.size() ? names[index] : "unknown"), 0, 0}, *m_found = true;
    }
    void flag(const char* name, bool& value, const char*) {
        if (join_path(m_prefix, name) == m_key) *m_out = {json(value), 0, 0}, *m_found = true;
    }
    template <class S>
    void section(const char* name, S& s) {
        const std::string path = join_path(m_prefix, name);
        if (m_key.rfind(path + ".", 0) != 0) return;
        FieldFinder inner(m_key, path, m_out, m_found);
        s.visit(inner);
    }

private:
    const std::string& m_key;
    std::string m_prefix;
    ConfigField* m_out;
    bool* m_found;
};

}  // namespace

ConfigField config_field(const SimConfig& config, const std::string& key) {
    SimConfig copy = config;
    ConfigField out;
    bool found = false;
    FieldFinder finder(key, "", &out, &found);
    copy.visit(finder);
    require(found, "config: unknown key '" + key + "'");
    return out;
}

json config_schema() {
    json out;
    SimConfig defaults;
    SchemaWriter writer(out);
    defaults.visit(writer);
    return out;
}

void validate(const SimConfig& config) {
    SimConfig copy = config;
    RangeValidator ranges;
    copy.visit(ranges);
    validate_model(config);
    // What may combine with what (techniques, unit kinds, structures, levels) is the resolution
    // step's (sim/resolve/rules.h), matched once per run against the structure it runs.
}

}  // namespace rtsim
