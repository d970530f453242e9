// The uniform grid's geometry (grid_layout.h).
#include "traces/accel/grid/grid_layout.h"

#include <cmath>

#include "traces/common/error.h"

namespace rtsim {

using nlohmann::json;

Aabb GridGeometry::bounds() const {
    Aabb b;
    for (int a = 0; a < 3; ++a) {
        b.lo[a] = plane(a, 0);
        b.hi[a] = plane(a, res[a]);
    }
    return b;
}

bool GridGeometry::slab_range(int axis, float lo, float hi, uint32_t* first, uint32_t* last) const {
    // Slab k = [plane k, plane k+1] meets [lo, hi] iff plane k+1 >= lo and plane k <= hi. Planes
    // rise with k, so both ends are found by bisection on the exact float planes.
    uint32_t a = 0, b = res[axis];
    while (a < b) {  // first k with plane(k + 1) >= lo
        const uint32_t m = a + (b - a) / 2;
        if (plane(axis, m + 1) >= lo) b = m;
        else a = m + 1;
    }
    *first = a;
    a = 0, b = res[axis];
    while (a < b) {  // first k with plane(k) > hi; the last slab is the one before
        const uint32_t m = a + (b - a) / 2;
        if (plane(axis, m) > hi) b = m;
        else a = m + 1;
    }
    *last = a - 1;
    return a > 0 && *first < res[axis] && *first <= *last;
}

json GridGeometry::to_json() const {
    return {{"resolution", {res[0], res[1], res[2]}},
            {"origin", {origin[0], origin[1], origin[2]}},
            {"cell_size", {cell[0], cell[1], cell[2]}}};
}

GridGeometry GridGeometry::from_json(const json& p, const std::string& source) {
    const std::string where = source + ": grid params";
    auto triple = [&](const char* key) -> const json& {
        require(p.is_object() && p.contains(key) && p.at(key).is_array() && p.at(key).size() == 3,
                where + ": '" + key + "' is missing or not 3 numbers");
        for (const json& v : p.at(key)) require(v.is_number(), where + ": '" + key + "' must be 3 numbers");
        return p.at(key);
    };
    GridGeometry g;
    const json &res = triple("resolution"), &origin = triple("origin"), &cell = triple("cell_size");
    for (int a = 0; a < 3; ++a) {
        require(res[a].is_number_unsigned() && res[a].get<uint64_t>() >= 1 && res[a].get<uint64_t>() <= (1u << 16),
                where + ": 'resolution' must be integers in [1, 65536]");
        g.res[a] = res[a].get<uint32_t>();
        g.origin[a] = origin[a].get<float>();
        g.cell[a] = cell[a].get<float>();
        require(std::isfinite(g.origin[a]), where + ": 'origin' must be finite");
        require(std::isfinite(g.cell[a]) && g.cell[a] > 0.0f, where + ": 'cell_size' must be finite and > 0");
        require(std::isfinite(g.plane(a, g.res[a])), where + ": the grid's far planes overflow");
        // Every cell must have a non-empty range of its own: planes strictly increasing.
        for (uint32_t k = 0; k < g.res[a]; ++k)
            require(g.plane(a, k) < g.plane(a, k + 1),
                    where + ": planes " + std::to_string(k) + " and " + std::to_string(k + 1) + " of axis " +
                        std::to_string(a) + " coincide (cell_size too small for the origin)");
    }
    return g;
}

}  // namespace rtsim
