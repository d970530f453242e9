// Builder settings as data (build_settings.h): the visitors over the builders' Config structs.
#include "traces/accel/build_settings.h"

#include <cmath>
#include <limits>
#include <set>
#include <sstream>
#include <type_traits>
#include <vector>

#include "traces/common/error.h"

namespace rtsim {

using nlohmann::json;

namespace {

std::string number_text(double x) {
    std::ostringstream out;
    out << x;
    return out.str();
}

class ValueWriter final : public SettingsVisitor {
public:
    explicit ValueWriter(json& out) : m_out(out) {}
    void field(const char* n, uint32_t& v, const char*, const char*, double, double) override { m_out[n] = v; }
    void field(const char* n, uint64_t& v, const char*, const char*, double, double) override { m_out[n] = v; }
    void field(const char* n, float& v, const char*, const char*, double, double) override { m_out[n] = v; }
    void flag(const char* n, bool& v, const char*) override { m_out[n] = v; }

private:
    json& m_out;
};

class SchemaWriter final : public SettingsVisitor {
public:
    explicit SchemaWriter(json& out) : m_out(out) {}
    void field(const char* n, uint32_t& v, const char* u, const char* d, double lo, double hi) override {
        add(n, "int", v, u, d, lo, hi);
    }
    void field(const char* n, uint64_t& v, const char* u, const char* d, double lo, double hi) override {
        add(n, "int", v, u, d, lo, hi);
    }
    void field(const char* n, float& v, const char* u, const char* d, double lo, double hi) override {
        add(n, "float", v, u, d, lo, hi);
    }
    void flag(const char* n, bool& v, const char* d) override { m_out[n] = {{"type", "bool"}, {"default", v}, {"doc", d}}; }

private:
    void add(const char* n, const char* type, const json& v, const char* u, const char* d, double lo, double hi) {
        m_out[n] = {{"type", type}, {"default", v}, {"unit", u}, {"min", lo}, {"max", hi}, {"doc", d}};
    }
    json& m_out;
};

/// Reads the overrides that name a visited field; remembers which keys it saw.
class OverrideReader final : public SettingsVisitor {
public:
    OverrideReader(const json& overrides, const std::string& what) : m_in(overrides), m_what(what) {}
    void field(const char* n, uint32_t& v, const char* u, const char*, double lo, double hi) override {
        number(n, v, u, lo, hi);
    }
    void field(const char* n, uint64_t& v, const char* u, const char*, double lo, double hi) override {
        number(n, v, u, lo, hi);
    }
    void field(const char* n, float& v, const char* u, const char*, double lo, double hi) override {
        number(n, v, u, lo, hi);
    }
    void flag(const char* n, bool& v, const char*) override {
        const json* j = take(n);
        if (!j) return;
        if (j->is_string() && (*j == "true" || *j == "false")) v = *j == "true";
        else if (j->is_boolean()) v = j->get<bool>();
        else fail(n, "must be true or false, got " + j->dump());
    }
    /// The keys of the overrides that no visited field took.
    std::string unknown() const {
        for (auto it = m_in.begin(); it != m_in.end(); ++it)
            if (!m_seen.count(it.key())) return it.key();
        return std::string();
    }
    std::string known() const {
        std::string s;
        for (const std::string& k : m_order) s += (s.empty() ? "" : ", ") + k;
        return s.empty() ? std::string("none") : s;
    }

private:
    const json* take(const char* name) {
        m_seen.insert(name);
        m_order.emplace_back(name);
        auto it = m_in.find(name);
        return it == m_in.end() ? nullptr : &*it;
    }
    [[noreturn]] void fail(const char* name, const std::string& why) const {
        throw Error(m_what + ": setting '" + name + "' " + why);
    }
    template <class T>
    void number(const char* n, T& v, const char* unit, double lo, double hi) {
        const json* j = take(n);
        if (!j) return;
        json value = *j;
        if (value.is_string()) value = json::parse(value.get<std::string>(), nullptr, false);
        if (!value.is_number() || value.is_boolean()) fail(n, "must be a number, got " + j->dump());
        const double d = value.get<double>();
        if (std::is_integral_v<T> && !(std::floor(d) == d)) fail(n, "must be an integer, got " + j->dump());
        if (!(std::isfinite(d) && d >= lo && d <= hi))
            fail(n, "= " + number_text(d) + " is out of range [" + number_text(lo) + ", " + number_text(hi) + "] " + unit);
        v = T(d);
    }
    const json& m_in;
    std::string m_what;
    std::set<std::string> m_seen;
    std::vector<std::string> m_order;
};

}  // namespace

json settings_values(const SettingsVisit& visit) {
    json out = json::object();
    ValueWriter w(out);
    visit(w);
    return out;
}

json settings_schema(const SettingsVisit& visit) {
    json out = json::object();
    SchemaWriter w(out);
    visit(w);
    return out;
}

void apply_settings(const SettingsVisit& visit, const json& overrides, const std::string& what) {
    require(overrides.is_object(), what + ": builder settings must be an object of key: value");
    if (overrides.empty()) return;
    OverrideReader r(overrides, what);
    visit(r);
    const std::string bad = r.unknown();
    if (!bad.empty()) throw Error(what + ": unknown setting '" + bad + "' (it takes: " + r.known() + ")");
}

void parse_setting(const std::string& assignment, json* overrides) {
    const size_t eq = assignment.find('=');
    require(eq != std::string::npos && eq > 0, "builder setting: expected key=value, got '" + assignment + "'");
    const std::string text = assignment.substr(eq + 1);
    json value = json::parse(text, nullptr, false);
    (*overrides)[assignment.substr(0, eq)] = value.is_discarded() ? json(text) : value;
}

}  // namespace rtsim
