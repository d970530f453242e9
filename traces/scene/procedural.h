#pragma once
// Scenes the project generates itself, written as glTF so they take the same path as real ones.
#include <cstdint>
#include <string>
#include <vector>

namespace rtsim {

struct ProceduralOptions {
    /// Exact triangle count of the hairball; up to millions (the other scenes have fixed detail).
    uint32_t hairball_triangles = 200000;
    uint64_t seed = 1;
};

/// Names of the built-in flat scenes: "cornell", "hairball", "teapot_stadium", "rotated_walls",
/// "aligned_walls", "terrain", "meadow", and the deforming "cloth", "exploding_hairball" and "skinned_tube" (Scene::animation set).
std::vector<std::string> procedural_scene_names();
/// Names of the built-in instanced scenes (procedural_forest.cpp): "forest" (72 x 72 instances,
/// about 4.6 x 10^8 triangles if flattened: two-level only) and "grove" (6 x 6 instances).
std::vector<std::string> instanced_procedural_scene_names();
/// Names of the built-in scenes of spheres (procedural_spheres.cpp; BVH kinds only), "particles"
/// and "furball", the furball's strands as capsules, "furball_capsules", nine of those placed
/// as instances, "furball_herd" (two levels), those flying apart over frames,
/// "exploding_furball" (deforming), and twins of icosahedra, "particles_mesh" and
/// "furball_mesh".
std::vector<std::string> sphere_procedural_scene_names();
bool is_procedural_scene(const std::string& name);

/// Writes scene `name` as `<dir>/<name>.gltf` (+ .bin) and returns the .gltf path.
/// Throws rtsim::Error for an unknown name, listing the known ones.
std::string write_procedural_scene(const std::string& name, const std::string& dir,
                                   const ProceduralOptions& options = {});

}  // namespace rtsim
