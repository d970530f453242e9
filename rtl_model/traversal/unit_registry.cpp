#include "rtl_model/traversal/unit_registry.h"

#include <array>

#include "rtl_model/traversal/mimd/mimd_unit.h"

namespace rtsim {

namespace {

using UnitFactory = std::unique_ptr<TraversalUnit> (*)(sc_core::sc_module_name, const UnitSetup&, uint32_t);

template <class Unit>
std::unique_ptr<TraversalUnit> make(sc_core::sc_module_name name, const UnitSetup& setup, uint32_t index) {
    return std::make_unique<Unit>(name, setup, index);
}

/// One line per unit kind, in UnitModel order.
constexpr std::array<UnitFactory, kUnitModelChoices.names.size()> kFactories{{
    make<MimdUnit>,  // mimd
}};

}  // namespace

std::unique_ptr<TraversalUnit> make_traversal_unit(sc_core::sc_module_name name, const UnitSetup& setup,
                                                   uint32_t index) {
    return kFactories[size_t(setup.config.model)](name, setup, index);
}

}  // namespace rtsim
