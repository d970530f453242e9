#pragma once
// Traversal units by name (traversal.model): the one place a unit kind is registered. Adding a
// kind is a folder beside mimd/ with a TraversalUnit subclass, its name in traversal_config.h's
// kUnitModelChoices and its line in unit_registry.cpp.
#include <memory>

#include "rtl_model/traversal/traversal_unit.h"

namespace rtsim {

/// Builds unit `index` of the kind `setup.config.model` names.
std::unique_ptr<TraversalUnit> make_traversal_unit(sc_core::sc_module_name name, const UnitSetup& setup,
                                                   uint32_t index);

}  // namespace rtsim
