#pragma once
// Reads glTF 2.0 (.gltf with external or embedded buffers, .glb) through tinygltf.
// Contract: returns a flattened Scene (flatten = false: meshes and instances indexed by
// Scene::index_instances(), for two-level tracing), or throws rtsim::Error whose message names the
// file and the offending element (mesh/primitive/accessor/node index and name). Never crashes on
// bad input.
#include <string>

#include "traces/scene/scene.h"

namespace rtsim {

Scene load_gltf(const std::string& path, bool flatten = true);

}  // namespace rtsim
