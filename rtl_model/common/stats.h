#pragma once
// Stats are declared by the block that produces them (docs/stats.md): each block keeps one table
// of StatDecl (key, unit, meaning, when it may be null or absent) beside its code. The block
// and the analytic level write their stats through a StatsWriter over that table (a key the
// table does not declare is an error, and so is a declared key left unwritten), the summary
// reads them through a StatsReader over the same table (a key renamed in one place fails loudly
// instead of reading null), and docs/stats.md's tables are generated from the tables
// (`rtsim-sim --dump-stats-schema`, scripts/gen_stats_doc.py).
#include <cstddef>
#include <functional>
#include <optional>
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

/// A stat declared with the one place its value comes from (Ramulator 2's `stats.add("row_hits",
/// m_row_hits)`): its declaration and a function of the source (a block's counters). A value of
/// std::nullopt leaves an optional key out.
template <class Source>
struct BoundStat {
    StatDecl decl;
    std::function<std::optional<nlohmann::json>(const Source&)> value;
};

/// A block's stats as bound declarations: the table is both the block's declaration (block(),
/// for the schema, docs and readers) and its writer, so a key cannot be declared and not
/// written, nor written undeclared.
template <class Source>
class StatTable {
public:
    StatTable(const char* path, std::vector<BoundStat<Source>> rows) : m_rows(std::move(rows)) {
        m_block.path = path;
        for (const BoundStat<Source>& r : m_rows) m_block.stats.push_back(r.decl);
    }
    const StatBlock& block() const { return m_block; }
    /// Sets every row's value from `source` into `out` (an object; other keys kept).
    void write(const Source& source, nlohmann::json& out) const {
        if (!out.is_object()) out = nlohmann::json::object();
        for (const BoundStat<Source>& r : m_rows) {
            std::optional<nlohmann::json> v = r.value(source);
            if (v) out[r.decl.key] = std::move(*v);
            else check_absent(r.decl);
        }
    }

private:
    void check_absent(const StatDecl& d) const;
    StatBlock m_block;
    std::vector<BoundStat<Source>> m_rows;
};

/// Throws naming the key when a bound stat that is not optional gave no value.
void require_optional_stat(const char* path, const StatDecl& d);

template <class Source>
void StatTable<Source>::check_absent(const StatDecl& d) const {
    require_optional_stat(m_block.path, d);
}

/// One block made of several (a unit kind's stats beside every unit's): each key once.
StatBlock merged_block(const char* path, const std::vector<const StatBlock*>& parts);

/// Every block's declaration, for the schema and docs (`rtsim-sim --dump-stats-schema`): each
/// owner registers its block from its own .cpp, so no list of blocks is kept anywhere else.
bool register_stat_block(const StatBlock& (*block)());
/// The registered blocks, ordered by path.
std::vector<const StatBlock*> registered_stat_blocks();
/// The registered block at `path`; throws rtsim::Error naming it when none is.
const StatBlock& registered_stat_block(const std::string& path);

#define RTSIM_STATS_CONCAT2(a, b) a##b
#define RTSIM_STATS_CONCAT(a, b) RTSIM_STATS_CONCAT2(a, b)
/// Registers `fn` (a function returning its block) from the block owner's .cpp.
#define RTSIM_REGISTER_STAT_BLOCK(fn)                                                               \
    namespace {                                                                                    \
    [[maybe_unused]] const bool RTSIM_STATS_CONCAT(rtsim_stat_block_registered_, __COUNTER__) =       \
        ::rtsim::register_stat_block(&fn);                                                         \
    }

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
