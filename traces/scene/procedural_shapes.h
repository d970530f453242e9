#pragma once
// Tessellated shapes for the procedural scenes, and the per-scene writers. Internal to traces/scene.
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "traces/scene/gltf_writer.h"
#include "traces/scene/procedural.h"

namespace rtsim {

/// Pi, for the shapes' angles.
constexpr double kPi = 3.14159265358979323846;

/// Closed surface of revolution about +Y: `profile` holds (radius, height) points from bottom to
/// top; `segments` around. Faces wound outward when the profile runs bottom to top.
void add_lathe(TriangleSoup& soup, const std::vector<glm::vec2>& profile, int segments,
               const glm::dmat4& m = glm::dmat4(1.0));
/// UV sphere of `rings` x `segments` quads (poles as triangle fans).
void add_sphere(TriangleSoup& soup, const Vec3& center, float radius, int rings, int segments);
/// Torus about the local Z axis (major radius R, minor r), transformed by m.
void add_torus(TriangleSoup& soup, float major, float minor, int major_segs, int minor_segs,
               const glm::dmat4& m);
/// Tube of circular section swept along `path` with per-point radius.
void add_tube(TriangleSoup& soup, const std::vector<Vec3>& path, const std::vector<float>& radius,
              int sides);

/// The hairball's strands (procedural_hairball.cpp): exactly `total` triangles, from `seed`.
TriangleSoup hairball_strands(uint32_t total, uint64_t seed);

/// Builds a Material in one line.
Material make_material(const std::string& name, const Vec3& color, float metallic, float roughness,
                       const Vec3& emissive = Vec3(0.0f));

// One writer per scene (procedural_*.cpp); each returns the .gltf path.
std::string write_cornell(const std::string& dir, const ProceduralOptions& options);
std::string write_hairball(const std::string& dir, const ProceduralOptions& options);
std::string write_teapot_stadium(const std::string& dir, const ProceduralOptions& options);
std::string write_rotated_walls(const std::string& dir, const ProceduralOptions& options);
std::string write_aligned_walls(const std::string& dir, const ProceduralOptions& options);
std::string write_terrain(const std::string& dir, const ProceduralOptions& options);
/// The terrain's hills under alpha-tested grass cards (a MASK material; procedural_terrain.cpp).
std::string write_meadow(const std::string& dir, const ProceduralOptions& options);
// Spheres (procedural_spheres.cpp).
std::string write_particles(const std::string& dir, const ProceduralOptions& options);
std::string write_furball(const std::string& dir, const ProceduralOptions& options);
std::string write_particles_mesh(const std::string& dir, const ProceduralOptions& options);
std::string write_furball_mesh(const std::string& dir, const ProceduralOptions& options);
std::string write_furball_capsules(const std::string& dir, const ProceduralOptions& options);
std::string write_furball_herd(const std::string& dir, const ProceduralOptions& options);
std::string write_exploding_furball(const std::string& dir, const ProceduralOptions& options);
std::string write_forest(const std::string& dir, const ProceduralOptions& options);
std::string write_grove(const std::string& dir, const ProceduralOptions& options);
// Deforming scenes (procedural_moving.cpp): their meshes move over frames (Scene::animation).
std::string write_cloth(const std::string& dir, const ProceduralOptions& options);
std::string write_exploding_hairball(const std::string& dir, const ProceduralOptions& options);
std::string write_skinned_tube(const std::string& dir, const ProceduralOptions& options);

}  // namespace rtsim
