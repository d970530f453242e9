#pragma once
// Every knob weighed (docs/stats.md, "verdict"): each resource the model has is a candidate,
// relaxed by one step of the config field that sizes it (doubled within its declared range, or a
// cost per operation halved), estimated, priced by the area model, ranked by gain and by gain per
// added mm^2; pairs whose joint relaxation gains much more than either alone are co-limits.
//
// A co-limit is what a single-knob verdict misses: with DRAM channels and L2 MSHRs both near
// their bound, doubling either leaves the other binding (a few percent), doubling both moves the
// machine to its next bound. The analytic level's closed form (sim/analytic/closed_form.h) is a
// max over bounds plus mean value analysis, so evaluating the pair shows it directly.
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sim/config/config.h"

namespace rtsim {

/// A config change that relaxes one resource: "key" from "from" to "to".
struct Relaxation {
    std::string key;
    nlohmann::json from, to;
};

/// The knob `key` doubled, within the range its config field declares; an empty key past it.
Relaxation doubled(const SimConfig& config, const std::string& key);
/// The knob `key` halved (a cost per operation), not below its declared minimum.
Relaxation halved(const SimConfig& config, const std::string& key);

/// One knob: the relaxation and the resource it relaxes (the names the verdict's `binding`
/// uses: `l2_mshrs`, `dram`, `box`, `l2_capacity`, `admission`, ...).
struct Knob {
    Relaxation relax;
    std::string resource;
    bool estimable = true;  ///< the analytic level models what the knob changes
    /// A structural knob (the structure, its leaves, treelets on or off, the execution model,
    /// sorting, prefetching): not a step of a resource but another design, estimated only on an
    /// analysis of its own (StructuralEstimator), else measured; `trace` when it needs another
    /// trace (the structure is the trace's).
    bool structural = false;
    bool trace = false;
};

/// What the verdict knows of the run's structure (the resolution step's facts), for the
/// structural knobs: the alternatives it offers and what they add to the area.
struct StructureTraits {
    std::string kind = "bvh2";        ///< the trace's structure ("two_level": its BLASes' kind below)
    std::string blas_kind;
    bool compressed_leaves = false;   ///< its leaves are compressed
    bool curved = false;              ///< the scene has spheres or capsules (no compressed leaves)
    bool treelet_partition = true;    ///< the kind partitions itself into treelets
    bool stack_addresses = false;     ///< its stacks hold addresses (traversal.stack_prefetch)
    bool quantized_boxes = false;     ///< its nodes hold 8-bit boxes (traversal.quantized_boxes)
    std::string trace;                ///< the run's trace, for the commands that measure
    std::string run;                  ///< the run's folder (its config.resolved.json and config.given.json), likewise
    std::string frame_policy;         ///< an animated trace's --frame-policy ("" for a still trace)
};

/// A knob of the unit kind's own (its registration's UnitKnob, handed over by the run loop).
struct KindKnob {
    std::string key;
    bool halve = false;     ///< relaxed by halving (else doubling)
    std::string resource;
    bool estimated = true;  ///< the analytic level can estimate it
};

/// What the verdict knows of the run's unit kind, from the run's resolution step: its own knobs,
/// and the kind whose analytic estimate stands in where the level has no lock-step groups.
struct UnitTraits {
    std::string name = "mimd";
    std::vector<KindKnob> knobs;
    std::string estimate_as;  ///< "" when the analytic level costs the kind itself
};

/// Every knob of this config that relaxes a resource: units, ray contexts, the pipelines of the
/// operation kinds in `ops`, the scheduler, L1 and L2 capacity, banks and MSHRs, DRAM channels,
/// the on-chip stack, the unit kind's own knobs and, with treelets on, the ray buffer, admission
/// and scheduling.
std::vector<Knob> every_knob(const SimConfig& config, const std::vector<OpKind>& ops,
                             const std::vector<KindKnob>& kind_knobs = {});

/// The structural alternatives to this run's design (Knob::structural), each one step: another
/// structure (wider, or compressed nodes) and compressed leaves (both a new trace), treelets on
/// or off, another execution model, ray sorting on or off, treelet prefetching on or off.
std::vector<Knob> structural_knobs(const SimConfig& config, const StructureTraits& structure);

/// The command that measures a structural knob: a re-run with `--set` (what --check-verdict
/// runs), or for a new structure the trace to make first.
std::string measure_command(const Knob& knob, const StructureTraits& structure);

/// A knob value as `--set` reads it (a string as is, numbers and switches as JSON writes them).
std::string value_text(const nlohmann::json& value);
/// `key=value`, as `--set` reads it.
inline std::string setting_text(const Relaxation& r) { return r.key + "=" + value_text(r.to); }

/// The cycles the estimator gives for a config; throws rtsim::Error for a config it refuses.
using CycleEstimate = std::function<double(const SimConfig&)>;

/// A structural knob's estimate: `speedup` 0 with `why_not` where none is made.
struct StructuralEstimate {
    double speedup = 0;
    std::string method;   ///< how it was made, for the verdict's text
    std::string why_not;  ///< why it was not
};

/// A structural knob's estimate for the run's config (VerdictEstimator::structural).
using StructuralEstimator = std::function<StructuralEstimate(const Knob&)>;

struct WeighInputs {
    const SimConfig& config;
    nlohmann::json instantiated;          ///< stats.json "instantiated" (the area model's input)
    CycleEstimate cycles;                 ///< unset when nothing can be estimated
    double base_cycles = 0;               ///< the estimator's cycles for `config`
    std::string not_covered;              ///< why the estimates do not describe this machine ("" if they do)
    std::map<std::string, double> evidence;  ///< resource -> share of context cycles pointing at it
    std::vector<KindKnob> kind_knobs = {};   ///< the unit kind's own knobs
    StructureTraits structure = {};          ///< for the structural knobs
    /// The DRAM bytes the estimator moves for a config (unset: not known): each knob's share of
    /// DRAM energy saved, and the tie-break between knobs whose estimates are within its error.
    CycleEstimate dram_bytes = {};
    StructuralEstimator structural = {};  ///< unset: every structural knob is measured, not estimated
};

/// {knobs (best first), top (three), top_per_mm2 (three), co_limits, structural}; each knob {key,
/// resource, from, to, speedup (null without an estimate), added_mm2, gain_per_mm2, evidence,
/// why_not, structural, measure (the command, structural knobs)}; `structural` lists those.
nlohmann::json weigh_knobs(const WeighInputs& in);

/// The relaxed config: `config` with every `key=to` of `knobs` set (validated); throws rtsim::Error.
SimConfig relaxed_config(const SimConfig& config, const std::vector<Relaxation>& knobs);

}  // namespace rtsim
