#pragma once
// Traversal unit kinds register themselves (docs/architecture.md, "Adding a traversal unit kind"),
// the way Ramulator 2 registers implementations: each kind's folder declares, once, in its own
// .cpp, its name, its factory, its own config section (traversal.<kind>.*), its own stats block
// and what it needs of a structure and a level, and one line registers it:
//
//   RTSIM_REGISTER_UNIT_KIND(simt_kind());
//
// Nothing central lists the kinds: traversal.model's choices, the config tree's sections, the
// stats schema, the resolution step's rules (sim/resolve/resolve.h) and `rtsim capabilities` all
// read this registry. The kinds' folders are globbed by rtl_model/traversal/CMakeLists.txt and
// linked whole, so a registration is never dropped by the linker.
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "rtl_model/common/config_section.h"
#include "rtl_model/common/stats.h"
#include "traces/common/work_counts.h"

namespace rtsim {

struct TraversalConfig;
struct UnitSetup;
struct RayJob;
struct StepOptions;
class Accel;
struct LocalityPartition;
class TraversalUnit;

/// What a lock-step kind's groups do on a sample of rays, stepped functionally (no time, no
/// memory model): what the analytic level needs to cost them (sim/analytic/estimate.cpp).
/// A window of consecutive rounds of a kind's functional group stepping (every group with rays
/// takes one step per round): the run's phases, as the analytic level prices them
/// (sim/analytic/estimate.cpp; MIMD contexts' windows are sim/analytic/profile.h's PhaseWindow).
struct GroupWindow {
    double rounds = 0, group_steps = 0, active_lanes = 0;
    /// Groups holding rays (stepping, or waiting for a step's line: GroupSetup::line_wait),
    /// summed over rounds.
    double groups = 0;
    /// Group steps by where their slowest line was likely served (the L1, the L2, DRAM:
    /// LineWait::level); all 0 without waits.
    std::array<double, 3> served{};
    /// Ends a round in the last of `windows` (its steps and lanes added by the caller): when the
    /// last holds `*window_rounds` rounds a new one opens, and at kMaxWindows neighbours merge and
    /// the windows double in length.
    static constexpr size_t kMaxWindows = 32;
    static void end_round(std::vector<GroupWindow>& windows, double* window_rounds);
};

struct GroupProfile {
    double rays = 0;             ///< rays of the sample
    double scheduler_steps = 0;  ///< scheduler phases the unit would take (its tally's steps)
    double group_steps = 0;      ///< warp or packet steps
    /// Of them, steps that take rays' states from the treelet ray buffer's SRAM (no memory
    /// read, no operation: the SRAM's latency)
    double buffer_steps = 0;
    double lane_slots = 0;       ///< group steps x rays per group
    double active_lanes = 0;     ///< rays that took part, summed over group steps
    /// Lanes holding a ray (stepping or waiting for their class), summed over group steps; 0: as
    /// lane_slots (a kind whose groups are always full)
    double occupied_lanes = 0;
    double lane_requests = 0;    ///< structure reads the stepping rays asked for
    double requests = 0;         ///< structure reads after coalescing (a packet's: one per step)
    /// Group steps by the operation kind they run (a warp step's kind, a packet's node or leaf
    /// step): what a group step's operations cost depends on it.
    std::array<double, kOpKindCount> kind_steps{};
    /// The rays' work as the groups walk it (packets change it) and walked alone.
    std::array<double, kWorkFieldCount> work{}, single_work{};
    /// The rounds in windows (GroupWindow), when the kind keeps them and one stepping covered
    /// every ray (a sum of several keeps none).
    std::vector<GroupWindow> phases;

    GroupProfile& operator+=(const GroupProfile& o);
    nlohmann::json to_json() const;
    static GroupProfile from_json(const nlohmann::json& j);
};

/// Where a group step's line is likely served (0: the L1, 1: the L2, 2: DRAM) and the rounds the
/// group waits for it before its next step.
struct LineWait {
    uint32_t rounds = 0, level = 0;
};

/// What a group profile needs of the machine beyond its traversal section.
struct GroupSetup {
    uint32_t line_bytes = 64;  ///< reads coalesced per line of this size
    /// Treelet scheduling, when on: the treelets rays queue by, and the ray buffer's admission
    /// (rays in the machine at most `admit_limit`; rays waiting in the SRAM below `capacity`
    /// unless `may_overflow`), as the ray buffer admits.
    const LocalityPartition* treelets = nullptr;
    uint64_t admit_limit = 0, capacity = 0;
    bool may_overflow = false;
    /// Rounds a group waits after its step reads `line` (a line number) on `unit`, the
    /// analysis's rounds as time (sim/analytic/round_waits.h); empty: no waits.
    std::function<LineWait(uint32_t unit, uint64_t line)> line_wait;
};

/// A kind's functional group stepping on the machine `traversal` describes: `rays_by_unit[u]`
/// the rays dispatch deals unit u, in order; the structure walked with `step`.
using GroupProfileFn =
    std::function<GroupProfile(const Accel&, const StepOptions& step, const TraversalConfig& traversal,
                               const std::vector<std::vector<RayJob>>& rays_by_unit, const GroupSetup& setup)>;

/// What a unit kind needs of the rest of a run; the resolution step matches these against the
/// structure's capabilities (traces/accel/capabilities.h), the level's and the techniques'.
struct UnitNeeds {
    /// Its rays step as one packet over one shared walk: the structure needs a packet kernel, and
    /// each ray's reference work is the packet loop's (HitChecker::set_packet_reference).
    bool packet_kernel = false;
    /// Its groups of rays step in lock-step: a level must cost lock-step groups.
    bool lock_step = false;
    /// Each ray walks with its own stack: per-ray techniques (restart trails, reduced-precision
    /// walks) can run on it.
    bool per_ray_stack = true;
    /// It takes rays one at a time from treelet queues and parks each alone: treelet scheduling.
    bool treelet_queues = true;
    /// Its rays trigger a treelet's prefetch as they step into it (treelet prefetching, with
    /// treelet queues or without).
    bool treelet_prefetch = true;
};

/// A knob of the kind's own the verdict may turn (sim/report/verdict_knobs.cpp).
struct UnitKnob {
    std::string key;       ///< its config key, e.g. "traversal.simt.lanes"
    bool halve = false;    ///< relaxed by halving (else by doubling)
    std::string resource;  ///< the resource it relaxes ("divergence", ...)
    bool estimated = true; ///< the analytic level can estimate it (else only a re-run measures it)
};

/// Every reference-walk parameter a packet kind asks the hit checker for.
struct PacketReference {
    uint32_t lanes = 0;       ///< rays per packet, in trace order
    float split_below = 0.0f; ///< PacketStepper::set_split_below
};

using UnitFactory = std::function<std::unique_ptr<TraversalUnit>(const char* name, const UnitSetup&, uint32_t index)>;

struct UnitKind {
    std::string name;     ///< traversal.model's value
    std::string summary;  ///< one line: what it models and after whom
    UnitFactory make_unit;
    /// Its own config section's defaults (traversal.<name>), or null when it has none.
    std::function<std::unique_ptr<ConfigSection>()> make_section;
    /// Its stats beyond unit_stats() (merged into model.units.<unit>), or null.
    const StatBlock* stats = nullptr;
    /// Rays that step together (1: each context alone); ray contexts are a whole number of groups.
    std::function<uint32_t(const TraversalConfig&)> group_size = [](const TraversalConfig&) { return 1u; };
    /// What takes rays of one treelet at a time under treelet scheduling, per unit: a MIMD unit
    /// runs one treelet (1), a SIMT unit one per warp (its groups).
    std::function<uint32_t(const TraversalConfig&)> treelet_consumers = [](const TraversalConfig&) { return 1u; };
    /// What a group is called in messages ("warp", "packet").
    std::string group_name = "context";
    UnitNeeds needs;
    std::vector<UnitKnob> knobs;
    /// Where a level cannot cost lock-step groups (the verdict's analytic estimates), the kind
    /// whose estimate stands in for this one with the same ray contexts.
    std::string estimate_as;
    /// The packet reference walk the hit checker checks its rays' work against (packet kernels).
    std::function<PacketReference(const TraversalConfig&)> packet_reference;
    /// Lock-step kinds: its groups stepped functionally, what the analytic level costs them from
    /// (null: the analytic level cannot cost the kind, and the resolution step says so).
    GroupProfileFn group_profile;

    /// Sets make_section to C's defaults (C: a struct with a template visit()).
    template <class C>
    void section() {
        make_section = [] { return std::make_unique<ConfigSectionOf<C>>(); };
    }
};

/// Adds a kind to the registry (at static initialisation); throws on a repeated name.
bool register_unit_kind(UnitKind kind);
/// Every registered kind, ordered by name.
std::vector<const UnitKind*> unit_kinds();
/// The kind named `name`; throws rtsim::Error naming traversal.model and the known kinds.
const UnitKind& unit_kind(const std::string& name);
/// Registered names, ordered, joined by ", ".
std::string unit_kind_names();

#define RTSIM_UNIT_KIND_CONCAT2(a, b) a##b
#define RTSIM_UNIT_KIND_CONCAT(a, b) RTSIM_UNIT_KIND_CONCAT2(a, b)
/// Registers the UnitKind `expr` once, from the unit kind's own .cpp (a unique name per use, so
/// kinds compiled in one unity batch do not collide).
#define RTSIM_REGISTER_UNIT_KIND(expr)                                                        \
    namespace {                                                                               \
    [[maybe_unused]] const bool RTSIM_UNIT_KIND_CONCAT(rtsim_unit_kind_registered_, __COUNTER__) = \
        ::rtsim::register_unit_kind(expr);                                                    \
    }

/// Each registered kind's own config section, by kind name: what TraversalConfig holds for
/// traversal.<kind>. Copies deeply; a kind's section is made at its defaults when first needed
/// (so configs made before every kind registered still see them all).
class UnitSections {
public:
    UnitSections() = default;
    UnitSections(const UnitSections& other);
    UnitSections& operator=(const UnitSections& other);
    UnitSections(UnitSections&&) = default;
    UnitSections& operator=(UnitSections&&) = default;

    /// Kind `kind`'s section, made at its defaults if absent; throws if the kind has none.
    ConfigSection& get(const std::string& kind) const;
    /// Kind `kind`'s section values as C (its registered type).
    template <class C>
    const C& of(const std::string& kind) const {
        return dynamic_cast<ConfigSectionOf<C>&>(get(kind)).value;
    }
    template <class C>
    C& of(const std::string& kind) {
        return dynamic_cast<ConfigSectionOf<C>&>(get(kind)).value;
    }

    /// v.section(kind, ...) for every registered kind with a section, in name order.
    template <class V>
    void visit(V& v) {
        for (const UnitKind* k : unit_kinds()) {
            if (!k->make_section) continue;
            ConfigSectionRef ref{get(k->name)};
            v.section(k->name.c_str(), ref);
        }
    }

private:
    mutable std::vector<std::pair<std::string, std::unique_ptr<ConfigSection>>> m_sections;
};

}  // namespace rtsim
