#pragma once
// What may combine with what, as data (docs/capabilities.md, generated from this table): each
// rule says what a technique, unit kind or trace asks for, what it needs of another side of the
// run (the structure, the unit kind, the level or another technique), why, and what to change.
// The resolution step (resolve.h) applies every rule once; nothing else refuses a combination.
#include <functional>
#include <string>
#include <vector>

#include "rtl_model/traversal/unit_kind.h"
#include "sim/config/config.h"
#include "sim/resolve/levels.h"
#include "sim/resolve/structure_facts.h"

namespace rtsim {

/// Everything a rule reads.
struct RunFacts {
    const SimConfig& config;
    const StructureFacts& structure;
    const UnitKind& unit;
    const LevelCapabilities& level;
};

/// The side of a run a rule matches the asking side against.
enum class RuleSide { structure, unit, level, technique };

struct Rule {
    std::string id;    ///< stable name, e.g. "restart_trail/structure"
    std::string asks;  ///< what asks, as the user sets it: "traversal.stack_overflow=restart_trail"
    std::function<bool(const RunFacts&)> active;  ///< it is asked for in this run
    RuleSide side;
    std::string needs;  ///< what it needs of that side: "a restart trail"
    std::function<bool(const RunFacts&)> met;  ///< the need holds
    std::string reason;  ///< one sentence: why it needs it
    std::string change;  ///< what to change
    /// A run it refuses (docs and the tests exercise every rule through the CLI): the structure
    /// to trace and the --set assignments. Empty: no registered structure meets the rule today
    /// (it guards kinds added later; the tests check that none does).
    std::string example_accel = "bvh2";
    std::vector<std::string> example_set;
};

/// Every rule, in a stable order.
const std::vector<Rule>& run_rules();
/// A technique set that has no effect on this run (pbrt-v4's ReportUnused): listed in the
/// summary, never refused.
struct Unused {
    std::string asks;
    std::string why;
};
std::vector<Unused> unused_settings(const RunFacts& facts);

/// The refusal `rule` makes of `facts`: both sides named, the reason and the change.
std::string refusal(const Rule& rule, const RunFacts& facts);

}  // namespace rtsim
