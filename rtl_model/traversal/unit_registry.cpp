#include "rtl_model/traversal/unit_registry.h"

#include <array>
#include <string>

#include "rtl_model/traversal/mimd/mimd_unit.h"
#include "rtl_model/traversal/packet/packet_unit.h"
#include "rtl_model/traversal/simt/simt_unit.h"
#include "traces/common/error.h"

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
    make<SimtUnit>,  // simt
    make<PacketUnit>,  // packet
}};

}  // namespace

std::unique_ptr<TraversalUnit> make_traversal_unit(sc_core::sc_module_name name, const UnitSetup& setup,
                                                   uint32_t index) {
    const UnitFactory make_unit = kFactories[size_t(setup.config.model)];
    require(make_unit != nullptr, std::string("model: traversal.model '") + kUnitModelChoices.name(setup.config.model) +
                                      "' has no unit built");
    return make_unit(name, setup, index);
}

}  // namespace rtsim
