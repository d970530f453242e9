#pragma once
// GltfWriter: builds a tinygltf::Model from indexed triangle lists, materials, lights and a camera
// and writes `<dir>/<name>.gltf` + `<name>.bin`. Used by the procedural scenes so that they take
// the same loading path as real scenes. Internal to traces/scene.
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "traces/scene/procedural_motion.h"
#include "traces/scene/scene.h"

namespace rtsim {

/// An indexed triangle list being assembled (object or world space).
struct TriangleSoup {
    std::vector<Vec3> vertices;
    std::vector<uint32_t> indices;  ///< 3 per triangle

    size_t triangle_count() const { return indices.size() / 3; }
    uint32_t add_vertex(const Vec3& v) {
        vertices.push_back(v);
        return uint32_t(vertices.size() - 1);
    }
    void add_triangle(uint32_t a, uint32_t b, uint32_t c) { indices.insert(indices.end(), {a, b, c}); }
    /// Quad a-b-c-d as two triangles, wound so the face normal points along `outward`.
    void add_quad(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& outward);
    /// Unit cube [-0.5, 0.5]^3 transformed by `m`, faces wound outward.
    void add_box(const glm::dmat4& m);
};

/// A skin's joint: its bind pose is `translation` from its parent (identity rotation); its motion
/// is one rotation per key time of its Skeleton (written as a LINEAR glTF animation channel).
struct SkinJoint {
    std::string name;
    int parent = -1;                   ///< index of the parent joint (parents come first), -1: root
    Vec3 translation{0.0f};            ///< from the parent joint (the root's: in the scene)
    std::vector<glm::quat> rotations;  ///< one per key time
};

/// The joints of a skinned mesh and the key times (seconds) their rotations are given at.
struct Skeleton {
    std::vector<SkinJoint> joints;
    std::vector<float> key_times;
};

/// Up to four joint influences per vertex of a skinned soup (glTF JOINTS_0 / WEIGHTS_0).
struct SkinWeights {
    std::vector<glm::u16vec4> joints;
    std::vector<glm::vec4> weights;
};

class GltfWriter {
public:
    GltfWriter();
    ~GltfWriter();
    GltfWriter(const GltfWriter&) = delete;
    GltfWriter& operator=(const GltfWriter&) = delete;

    /// Returns the glTF material index (emissive strength > 1 uses KHR_materials_emissive_strength).
    int add_material(const Material& m);
    /// Adds a mesh with one primitive per (soup, material) pair; returns the glTF mesh index.
    int add_mesh(const std::string& name, const std::vector<std::pair<const TriangleSoup*, int>>& parts);
    /// Adds a mesh of spheres (docs/accel.md, "Spheres and capsules"): one POINTS primitive whose POSITION
    /// are the centres and whose _RADIUS the radii; returns the glTF mesh index.
    int add_sphere_mesh(const std::string& name, const std::vector<Vec3>& centres, const std::vector<float>& radii,
                        int material);
    /// Adds a mesh of capsules: one LINES primitive of `segments` (index pairs into `vertices`),
    /// each vertex's radius its _RADIUS; returns the glTF mesh index.
    int add_capsule_mesh(const std::string& name, const std::vector<Vec3>& vertices, const std::vector<float>& radii,
                         const std::vector<uint32_t>& segments, int material);
    /// Marks glTF mesh `mesh` as deforming with `motion` (written as its extras.rtsimMotion).
    void set_mesh_motion(int mesh, const ProceduralMotion& motion);
    /// Adds a root node placing `mesh` with `transform` (identity: no matrix written).
    void add_mesh_node(const std::string& name, int mesh, const glm::dmat4& transform = glm::dmat4(1.0));
    /// Adds `soup` skinned by `skeleton`: a mesh node with its skin (the joints as nodes, the
    /// inverse bind matrices of the bind pose) and one animation of the joints' rotations.
    void add_skinned_mesh_node(const std::string& name, const TriangleSoup& soup, int material,
                               const SkinWeights& weights, const Skeleton& skeleton);
    /// Perspective camera at `eye` looking at `target`.
    void add_camera(const std::string& name, const Vec3& eye, const Vec3& target, float yfov,
                    float aspect);
    /// KHR_lights_punctual light; for directional/spot lights `target` sets the direction.
    void add_light(const std::string& name, LightType type, const Vec3& position, const Vec3& target,
                   const Vec3& color, float intensity);
    /// Writes `<dir>/<name>.gltf` and `<dir>/<name>.bin`; returns the .gltf path.
    std::string write(const std::string& dir, const std::string& name);

private:
    struct Impl;
    Impl* m_impl;
};

}  // namespace rtsim
