#pragma once
// Config sections known only at run time: a unit kind's own section (traversal.simt, ...),
// registered from the kind's folder (rtl_model/traversal/unit_kind.h) rather than listed in a
// shared struct. The config tree's visitors are templates (sim/config/config.cpp); a registered
// section is visited through ConfigVisitor, a virtual interface each template visitor is wrapped
// in (ErasedVisitor), so a kind's visit() reads like any block's: field(), choice(), flag().
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "rtl_model/common/choice.h"

namespace rtsim {

/// The visitor calls a config struct's visit() makes, behind virtual functions.
class ConfigVisitor {
public:
    virtual ~ConfigVisitor() = default;
    virtual void field(const char* name, uint32_t& value, const char* unit, const char* doc, double lo, double hi) = 0;
    virtual void field(const char* name, uint64_t& value, const char* unit, const char* doc, double lo, double hi) = 0;
    virtual void field(const char* name, double& value, const char* unit, const char* doc, double lo, double hi) = 0;
    virtual void flag(const char* name, bool& value, const char* doc) = 0;
    /// A choice as an index into `names` (an enum's Choices, erased).
    virtual void choice_index(const char* name, size_t& index, const std::vector<const char*>& names,
                              const char* doc) = 0;

    template <class E, size_t N>
    void choice(const char* name, E& value, const Choices<E, N>& choices, const char* doc) {
        size_t index = static_cast<size_t>(value);
        choice_index(name, index, std::vector<const char*>(choices.names.begin(), choices.names.end()), doc);
        value = static_cast<E>(index);
    }
};

/// A template visitor V (field, flag, choice_names) as a ConfigVisitor.
template <class V>
class ErasedVisitor final : public ConfigVisitor {
public:
    explicit ErasedVisitor(V& v) : m_v(v) {}
    void field(const char* n, uint32_t& x, const char* u, const char* d, double lo, double hi) override {
        m_v.field(n, x, u, d, lo, hi);
    }
    void field(const char* n, uint64_t& x, const char* u, const char* d, double lo, double hi) override {
        m_v.field(n, x, u, d, lo, hi);
    }
    void field(const char* n, double& x, const char* u, const char* d, double lo, double hi) override {
        m_v.field(n, x, u, d, lo, hi);
    }
    void flag(const char* n, bool& x, const char* d) override { m_v.flag(n, x, d); }
    void choice_index(const char* n, size_t& i, const std::vector<const char*>& names, const char* d) override {
        m_v.choice_names(n, i, names, d);
    }

private:
    V& m_v;
};

/// One registered section's values: a copyable config struct behind a virtual visit().
class ConfigSection {
public:
    virtual ~ConfigSection() = default;
    virtual std::unique_ptr<ConfigSection> clone() const = 0;
    virtual void visit(ConfigVisitor& v) = 0;
};

/// The section holding a C (a struct with a template visit(), fields of the types above).
template <class C>
class ConfigSectionOf final : public ConfigSection {
public:
    C value;
    std::unique_ptr<ConfigSection> clone() const override { return std::make_unique<ConfigSectionOf>(*this); }
    void visit(ConfigVisitor& v) override { value.visit(v); }
};

/// A section as the template visitors see it: v.section(name, ref) calls ref.visit(inner).
struct ConfigSectionRef {
    ConfigSection& section;
    template <class V>
    void visit(V& v) {
        ErasedVisitor<V> erased(v);
        section.visit(erased);
    }
};

}  // namespace rtsim
