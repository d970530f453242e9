#pragma once
// One vocabulary for the resources a run can be bound by (docs/verdict.md, "One vocabulary"):
// the verdict's `binding`, the roofline's ceilings and `bound`, and the analytic level's bounds
// and `binding` all use these names, and every text that names a resource uses its label. A
// reader who sees "l2_banks" in the roofline and "l2_banks" in the verdict knows they are the same
// thing; one who sees a knob named for one resource and a ceiling for another is told whether
// the knob relaxes that ceiling (knob_relaxes).
#include <string>
#include <vector>

#include "sim/config/config.h"

namespace rtsim {

struct ResourceInfo {
    const char* name;   ///< as stats name it: "l1_mshrs", "dram", "box", ...
    const char* label;  ///< what a person calls it
    const char* busy;   ///< the model.utilization entry that shows it busy ("" if none)
};

/// Every resource besides the pipelines (which are named by their operation kind: "box",
/// "triangle", ...; their label is "<kind> pipelines" and their utilisation "pipe_<kind>").
const std::vector<ResourceInfo>& resource_table();

/// The label of a resource name (an operation kind: "<kind> pipelines"; unknown: the name).
std::string resource_label(const std::string& resource);
/// The utilisation that shows a resource busy ("" if none).
std::string resource_busy(const std::string& resource);
/// True when `resource` is a pipeline kind (sets *kind).
bool resource_op_kind(const std::string& resource, OpKind* kind);

/// Whether each unit has its own `resource`, so more traversal units relax it (the ray
/// contexts' latency hiding, the scheduler, unshared pipelines, the L1's MSHRs and banks).
bool resource_per_unit(const SimConfig& config, const std::string& resource);

/// The resources a knob (a config key) relaxes, directly or through what it removes: more units
/// relax every per-unit resource; a larger L2 removes misses, so DRAM traffic and the L2's MSHR
/// time; a larger L1 removes L2 accesses and L1 MSHR time; more DRAM channels shorten the L2's
/// MSHR hold under load. Used to say whether the named knob relaxes the roofline's lowest ceiling
/// and the analytic binding.
std::vector<std::string> knob_relaxes(const SimConfig& config, const std::string& key);

}  // namespace rtsim
