#pragma once
// The one config tree of the simulator (docs/architecture.md, rule 5): the model's config
// (rtl_model/top/model_config.h: the blocks' configs and the level flags) plus the harness's own
// sections (sampling, energy, the analytic level). Each struct lists its fields once in visit()
// with name, unit, range and a one-line doc; the JSON reader, writer, schema dump (for the Python
// dataclasses) and validate() are all visitors, so a field cannot be documented, defaulted or
// range-checked in one place and not another. Choices are enums, parsed once.
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "rtl_model/top/model_config.h"
#include "sim/analytic/analytic_config.h"
#include "sim/report/energy_config.h"
#include "sim/sampling/sampling_config.h"

namespace rtsim {

struct SimConfig : ModelConfig {
    SamplingConfig sampling;
    EnergyConfig energy;  ///< the energy and area model's technology (sim/report/energy_area.h)
    AnalyticConfig analytic;  ///< the analytic level (sim/analytic/analytic_config.h)

    template <class V>
    void visit(V& v) {
        ModelConfig::visit(v);
        v.section("sampling", sampling);
        v.section("energy", energy);
        v.section("analytic", analytic);
    }
};

/// Reads a config from JSON over the defaults; unknown keys and bad values throw rtsim::Error
/// naming the key path (e.g. "l1.size_kib").
SimConfig config_from_json(const nlohmann::json& j, const SimConfig& base = {});
/// Applies "key.path=value" (value parsed by the field's type).
void config_set(SimConfig& config, const std::string& assignment);
nlohmann::json config_to_json(const SimConfig& config);
/// One field as the tree declares it: its value (JSON) and range (choices and flags: 0, 0).
struct ConfigField {
    nlohmann::json value;
    double min = 0, max = 0;
};
/// The field at a dotted key path ("l1.mshrs"); throws rtsim::Error naming an unknown key.
ConfigField config_field(const SimConfig& config, const std::string& key);
/// Every field with default, unit, range, choices and doc: the schema the Python side mirrors.
nlohmann::json config_schema();
/// Range checks plus each block's own field rules (cache geometry, DRAM address fields); throws
/// rtsim::Error naming the field. What combines with what is the resolution step's
/// (sim/resolve/resolve.h).
void validate(const SimConfig& config);

}  // namespace rtsim
