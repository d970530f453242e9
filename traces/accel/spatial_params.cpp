// The root cell in an image's params (spatial_params.h).
#include "traces/accel/spatial_params.h"

#include <cmath>

#include "traces/common/error.h"

namespace rtsim {

using nlohmann::json;

json root_cell_json(const Aabb& b) {
    return {{"bounds", {{b.lo.x, b.lo.y, b.lo.z}, {b.hi.x, b.hi.y, b.hi.z}}}};
}

Aabb root_cell_from_json(const json& p, const std::string& where) {
    const bool shaped = p.is_object() && p.contains("bounds") && p.at("bounds").is_array() &&
                        p.at("bounds").size() == 2 && p.at("bounds")[0].is_array() && p.at("bounds")[1].is_array() &&
                        p.at("bounds")[0].size() == 3 && p.at("bounds")[1].size() == 3;
    require(shaped, where + ": 'bounds' is missing or not [[lo x, y, z], [hi x, y, z]]");
    Aabb b;
    for (int s = 0; s < 2; ++s)
        for (int a = 0; a < 3; ++a) {
            const json& v = p.at("bounds")[s][a];
            require(v.is_number() && std::isfinite(v.get<double>()), where + ": 'bounds' must be finite numbers");
            (s == 0 ? b.lo : b.hi)[a] = v.get<float>();
        }
    for (int a = 0; a < 3; ++a)
        require(b.lo[a] <= b.hi[a], where + ": 'bounds' has lo > hi on axis " + std::to_string(a));
    return b;
}

}  // namespace rtsim
