#pragma once
// The run's one resolution step (docs/architecture.md, "Components that negotiate once"): the
// config's unit kind and techniques matched against the structure's capabilities and the level's,
// once, before anything is built. Every refusal of a combination comes from the rules table
// (rules.h), names both sides and the field to change; what resolves is a RunSetup: the config
// with its derived fields filled (and the list of them), the StepOptions the steppers walk with,
// the unit kind, and what the hit checker needs.
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rtl_model/traversal/unit_kind.h"
#include "sim/config/config.h"
#include "sim/resolve/levels.h"
#include "sim/resolve/rules.h"
#include "sim/resolve/structure_facts.h"
#include "traces/accel/step_options.h"

namespace rtsim {

/// A field the resolution step filled in because the config left it to the run.
struct DerivedField {
    std::string key;
    nlohmann::json value;
    std::string why;
};

struct RunSetup {
    SimConfig config;  ///< resolved: what config.resolved.json holds
    StructureFacts structure;
    LevelCapabilities level;
    const UnitKind* unit = nullptr;
    StepOptions step;  ///< what every stepper of the run walks with
    /// The packet reference the hit checker takes each group's work from (packet kinds).
    std::optional<PacketReference> packet_reference;
    std::vector<DerivedField> derived;
    std::vector<Unused> unused;

    /// {derived: [{key, value, why}], unused: [{key, why}]}: what the summary reports.
    nlohmann::json to_json() const;
};

/// Resolves `config` for a run over `structure`; throws rtsim::Error with the first rule the
/// combination breaks (after the config's own range and field checks, validate()).
RunSetup resolve_run(const SimConfig& config, const StructureFacts& structure);

/// Resolves each run of the JSON list in file `path`, [{config, accel, blas_kind,
/// compressed_leaves}] (config: a patch over the defaults), against facts made from the kind
/// names: [{ok, error, resolved}] in the same order; a run is refused as resolve_run and the
/// model's memory estimate (check_sim_memory, without the image) refuse it. Sweeps check a spec this way
/// before any trace exists. Throws rtsim::Error naming the file when it is not such a list.
nlohmann::json check_runs(const std::string& path);

/// The names Python reads from the C++ declarations (`rtsim-sim --dump-names`, written into the
/// package at build time): {ray_kinds, data_kinds, op_kinds, unit_kinds, accel_kinds}, each in
/// declaration order.
nlohmann::json declared_names();

/// The rules and what composes with what: {rules: [...], unit_kinds: [...], structures: [...],
/// matrix: ...}, printed by `rtsim capabilities` and generated into docs/capabilities.md.
nlohmann::json capability_table();
/// The same as Markdown (docs/capabilities.md's generated part).
std::string capability_markdown();

}  // namespace rtsim
