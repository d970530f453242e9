#pragma once
// The stats of a traversal unit (model.units.<unit>): what every kind writes (unit_stats()) and,
// beside it, the chosen kind's own block (UnitKind::stats, declared in the kind's folder).
#include <string>

#include "rtl_model/common/stats.h"

namespace rtsim {

/// The stats every traversal unit writes (model.units.<unit>; the analytic level's too), whatever
/// its kind; keys only some modes write are optional.
const StatBlock& unit_stats();
/// unit_stats() and the stats of unit kind `kind` (its registered block), merged: what a unit of
/// that kind writes and is checked against. Throws naming traversal.model for an unknown kind.
const StatBlock& unit_stats_of(const std::string& kind);

}  // namespace rtsim
