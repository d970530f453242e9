// The procedural scene registry: names to writers.
#include "traces/scene/procedural.h"

#include "traces/common/error.h"
#include "traces/scene/procedural_shapes.h"

namespace rtsim {

namespace {

struct Entry {
    const char* name;
    std::string (*write)(const std::string&, const ProceduralOptions&);
};

const Entry kScenes[] = {
    {"cornell", write_cornell},
    {"hairball", write_hairball},
    {"teapot_stadium", write_teapot_stadium},
    {"rotated_walls", write_rotated_walls},
    {"aligned_walls", write_aligned_walls},
    {"terrain", write_terrain},
    {"meadow", write_meadow},
    {"cloth", write_cloth},
    {"exploding_hairball", write_exploding_hairball},
    {"skinned_tube", write_skinned_tube},
};

/// Instanced scenes: not in procedural_scene_names(), which the per-structure tests sweep
/// flattened (the forest cannot be flattened).
const Entry kInstancedScenes[] = {
    {"forest", write_forest},
    {"grove", write_grove},
};

/// Scenes of spheres and their tessellated twins: not in procedural_scene_names() either, as
/// only the BVH kinds store spheres (capabilities.h) and the per-structure tests sweep every
/// kind over those (the twins' 0.8 and 1.9 million triangles would slow them).
const Entry kSphereScenes[] = {
    {"particles", write_particles},
    {"furball", write_furball},
    {"furball_capsules", write_furball_capsules},
    {"furball_herd", write_furball_herd},
    {"exploding_furball", write_exploding_furball},
    {"particles_mesh", write_particles_mesh},
    {"furball_mesh", write_furball_mesh},
};

}  // namespace

std::vector<std::string> sphere_procedural_scene_names() {
    std::vector<std::string> names;
    for (const Entry& e : kSphereScenes) names.push_back(e.name);
    return names;
}

std::vector<std::string> procedural_scene_names() {
    std::vector<std::string> names;
    for (const Entry& e : kScenes) names.push_back(e.name);
    return names;
}

std::vector<std::string> instanced_procedural_scene_names() {
    std::vector<std::string> names;
    for (const Entry& e : kInstancedScenes) names.push_back(e.name);
    return names;
}

bool is_procedural_scene(const std::string& name) {
    for (const Entry& e : kScenes)
        if (name == e.name) return true;
    for (const Entry& e : kInstancedScenes)
        if (name == e.name) return true;
    for (const Entry& e : kSphereScenes)
        if (name == e.name) return true;
    return false;
}

std::string write_procedural_scene(const std::string& name, const std::string& dir,
                                   const ProceduralOptions& options) {
    for (const Entry& e : kScenes)
        if (name == e.name) return e.write(dir, options);
    for (const Entry& e : kInstancedScenes)
        if (name == e.name) return e.write(dir, options);
    for (const Entry& e : kSphereScenes)
        if (name == e.name) return e.write(dir, options);
    std::string known;
    for (const Entry& e : kScenes) known += std::string(known.empty() ? "" : ", ") + e.name;
    for (const Entry& e : kInstancedScenes) known += std::string(", ") + e.name;
    for (const Entry& e : kSphereScenes) known += std::string(", ") + e.name;
    throw Error("unknown procedural scene '" + name + "' (known: " + known + ")");
}

}  // namespace rtsim
