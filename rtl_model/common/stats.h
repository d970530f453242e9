#pragma once
// Stats are declared by the block that produces them (docs/stats.md): each block keeps one table
// of StatDecl (key, unit, meaning, when it may be null or absent) beside its code. The block
// and the analytic level write their stats through a StatsWriter over that table (a key the
// table does not declare is an error, and so is a declared key left unwritten), the summary
// reads them through a StatsReader over the same table (a key renamed in one place fails loudly
// instead of reading null), and docs/stats.md's tables are generated from the tables
// (`rtsim-sim --dump-stats-schema`, scripts/gen_stats_doc.py).
#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace rtsim {

struct StatDecl {
    const char* key;
    const char* unit;     ///< "" when the value has no unit (a name, a flag, an object)
    const char* meaning;  ///< one line, Markdown
    bool timed = false;     ///< null where the level has no simulated time (functional, analytic)
    bool optional = false;  ///< written only in some runs (the meaning says which)
};

/// A block's stats: where they sit in stats.json and what they are. docs/stats.md keeps the
/// prose around each block's table; the table itself is generated from this.
struct StatBlock {
    const char* path;  ///< e.g. "model.units.<unit>"
    std::vector<StatDecl> stats;

    const StatDecl* find(const std::string& key) const;
    /// The declaration of `key`; throws rtsim::Error naming the block and key when undeclared.
    const StatDecl& at(const std::string& key) const;
    /// Throws naming the key if `j` has a key the block does not declare, or lacks a
    /// non-optional one it declares.
    void check(const nlohmann::json& j) const;
    /// {path, stats: [{key, unit, meaning, timed, optional}]}.
    nlohmann::json schema_json() const;
};

/// Writes one block's stats object; set() refuses undeclared keys, done() requires every
/// non-optional key to be set.
class StatsWriter {
public:
    StatsWriter(const StatBlock& block, nlohmann::json& out) : m_block(block), m_out(out) {
        if (!m_out.is_object()) m_out = nlohmann::json::object();
    }
    template <class T>
    StatsWriter& set(const char* key, const T& value) {
        m_block.at(key);
        m_out[key] = value;
        return *this;
    }
    /// Copies every key of `j` (an object of declared keys, e.g. a shared counters' json).
    StatsWriter& merge(const nlohmann::json& j);
    /// Sets every declared `timed` key to null: a level without simulated time (analytic).
    StatsWriter& untimed();
    /// Checks the object against the block's table (StatBlock::check).
    void done() const { m_block.check(m_out); }

private:
    const StatBlock& m_block;
    nlohmann::json& m_out;
};

/// Reads one block's stats object by declared key.
class StatsReader {
public:
    StatsReader(const StatBlock& block, const nlohmann::json& j) : m_block(block), m_json(j) {}
    /// The value (null when the level has none); throws naming block and key when the key is
    /// undeclared, or declared, not optional and missing.
    const nlohmann::json& operator[](const char* key) const;

private:
    const StatBlock& m_block;
    const nlohmann::json& m_json;
};

}  // namespace rtsim
