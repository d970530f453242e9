#pragma once
// Lights added to a scene that has none (`rtsim trace --lights sun`): Sponza and most scanned
// models carry no KHR_lights_punctual light and no emissive material, so by rule 10 their traces
// hold no shadow rays; a study of any-hit traversal needs them by choice. What was added is
// written to the manifest (workload.lights_added), so a trace never passes for the scene's own.
#include <string>

#include <nlohmann/json.hpp>

#include "traces/scene/scene.h"

namespace rtsim {

/// The choices of --lights: "none" (the default) or "sun".
bool known_added_lights(const std::string& which);

/// Adds the lights `which` names to a scene without lights of its own (no punctual light and no
/// emissive material); a scene with lights keeps them and gets nothing. "sun": one directional
/// light from high above the scene (y up, as glTF's), tilted so shadows fall slantwise. Returns
/// what was done, for the manifest: {"requested", "added": [lights], "why"}. Throws rtsim::Error
/// on an unknown choice.
nlohmann::json add_lights(Scene& scene, const std::string& which);

}  // namespace rtsim
