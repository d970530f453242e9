// Lights added by choice (added_lights.h).
#include "traces/raygen/added_lights.h"

#include <algorithm>

#include "traces/common/error.h"

namespace rtsim {

bool known_added_lights(const std::string& which) { return which.empty() || which == "none" || which == "sun"; }

nlohmann::json add_lights(Scene& scene, const std::string& which) {
    require(known_added_lights(which), "lights: unknown choice '" + which + "' (choose none or sun)");
    nlohmann::json out = {{"requested", which.empty() ? "none" : which}, {"added", nlohmann::json::array()}};
    if (which.empty() || which == "none") {
        out["why"] = "none requested";
        return out;
    }
    const bool emissive = std::any_of(scene.materials.begin(), scene.materials.end(),
                                      [](const Material& m) { return m.is_emissive(); });
    if (!scene.lights.empty() || emissive) {
        out["why"] = "the scene has lights of its own: none added";
        return out;
    }
    // The direction the light points to (glTF's -z of the light's node): down and slantwise.
    Light sun;
    sun.name = "rtsim sun (--lights sun)";
    sun.type = LightType::directional;
    sun.direction = glm::normalize(Vec3(-0.3f, -1.0f, -0.2f));
    sun.intensity = 3.0f;
    scene.lights.push_back(sun);
    out["added"].push_back({{"name", sun.name},
                            {"type", "directional"},
                            {"direction", {sun.direction.x, sun.direction.y, sun.direction.z}},
                            {"intensity", sun.intensity}});
    out["why"] = "the scene has no punctual light and no emissive material";
    return out;
}

}  // namespace rtsim
