#pragma once
// The scene as the tracer sees it: unique meshes in object space, instances placing them in the
// world, materials, lights and cameras, plus the flattened world-space triangle list.
//
// Stable primitive ids. Instances are numbered in the order a depth-first walk of the glTF
// default scene meets them: root nodes in `scene.nodes` order, children in `node.children`
// order, a node's mesh before its children; a node with EXT_mesh_gpu_instancing yields one
// instance per entry, in accessor order. Within an instance, triangles follow the mesh's
// primitives in order and each primitive's indices in order (strips and fans converted to
// triangle lists first). The primitive id of a triangle is instance.prim_base + its index in
// the mesh, so ids run 0..N-1 over the whole scene and `triangles()` is indexed by them.
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "traces/common/aabb.h"
#include "traces/scene/mesh_animation.h"

namespace rtsim {

enum class AlphaMode : uint8_t { opaque = 0, mask = 1, blend = 2 };

/// The glTF material texture slots a shader reads (glTF 2.0 section 3.9), in a fixed order.
enum class TextureSlot : uint8_t { base_color = 0, normal = 1, metallic_roughness = 2, emissive = 3, occlusion = 4 };
constexpr int kTextureSlotCount = 5;

/// What a glTF material says about one texture slot; traces/shading turns it into a texture.
struct MaterialTexture {
    enum class Source : uint8_t { none = 0, image = 1, stripped = 2 };
    Source source = Source::none;
    int32_t image = -1;        ///< glTF image index (Source::image)
    uint32_t width = 0;        ///< the image's size from its header; 0 if it could not be read
    uint32_t height = 0;
};

struct Material {
    std::string name;
    glm::vec4 base_color{1.0f};
    float metallic = 1.0f;   ///< glTF default
    float roughness = 1.0f;  ///< glTF default
    AlphaMode alpha_mode = AlphaMode::opaque;
    float alpha_cutoff = 0.5f;
    float transmission = 0.0f;  ///< KHR_materials_transmission
    float ior = 1.5f;           ///< KHR_materials_ior
    Vec3 emissive{0.0f};        ///< emissiveFactor x KHR_materials_emissive_strength
    /// Fraction of texels passing the alpha cutoff (extras.textureAlphaCoverage); 1 if unknown.
    /// Drives the deterministic stochastic alpha test of MASK materials.
    float alpha_coverage = 1.0f;
    /// Texture slots as the file gives them: an image, a texture stripped from a shared scene
    /// (extras.strippedTextures), or none.
    MaterialTexture textures[kTextureSlotCount];
    /// extras.factorsBakedFromKhronosTextureMeans: the factors are the means of textures the
    /// file no longer carries (which ones it does not say).
    bool textures_baked = false;

    bool is_emissive() const { return emissive.x > 0.0f || emissive.y > 0.0f || emissive.z > 0.0f; }
};

enum class LightType : uint8_t { point = 0, spot = 1, directional = 2 };

/// KHR_lights_punctual light, in world space.
struct Light {
    std::string name;
    LightType type = LightType::point;
    Vec3 position{0.0f};
    Vec3 direction{0.0f, 0.0f, -1.0f};  ///< direction the light points to (spot, directional)
    Vec3 color{1.0f};
    float intensity = 1.0f;
    float range = 0.0f;  ///< 0 means infinite
    float inner_cone = 0.0f;
    float outer_cone = 0.785398163f;
};

/// Perspective camera, in world space (orthographic cameras are read as perspective with a
/// warning in the manifest; rtsim only generates pinhole rays).
struct Camera {
    std::string name;
    Vec3 eye{0.0f};
    Vec3 forward{0.0f, 0.0f, -1.0f};  ///< unit
    Vec3 up{0.0f, 1.0f, 0.0f};        ///< unit, orthogonal to forward
    float yfov = 0.8f;                ///< radians
    float aspect = 0.0f;              ///< 0: take it from the image resolution
};

/// Unique geometry in object space: one glTF mesh, all its triangle primitives concatenated.
struct Mesh {
    std::string name;
    std::vector<Vec3> positions;      ///< 3 per triangle (v0, v1, v2)
    std::vector<uint32_t> materials;  ///< one per triangle, index into Scene::materials
    /// TEXCOORD_0, 3 per triangle like positions; empty when no primitive has it (a mesh with
    /// some primitives lacking it gets (0, 0) there).
    std::vector<glm::vec2> uvs;
    /// Curved primitives (docs/accel.md, "Spheres and capsules"): one radius per primitive (a
    /// capsule's at its first end), 0 for a triangle; empty when the mesh has none. A sphere's
    /// three positions are its centre, a capsule's its two ends and the second end again.
    std::vector<float> radii;
    /// A capsule's radius at its second end, per primitive; empty when every capsule of the mesh
    /// has one radius (then it is radii's).
    std::vector<float> end_radii;
    float end_radius(size_t prim) const { return end_radii.empty() ? radii[prim] : end_radii[prim]; }
    size_t triangle_count() const { return materials.size(); }
    bool is_curved(size_t prim) const { return !radii.empty() && radii[prim] > 0.0f; }
    bool is_capsule(size_t prim) const { return is_curved(prim) && positions[3 * prim] != positions[3 * prim + 1]; }
};

/// One placement of a mesh in the world.
struct Instance {
    uint32_t mesh = 0;
    glm::dmat4 object_to_world{1.0};
    uint32_t prim_base = 0;  ///< primitive id of the mesh's first triangle in this instance
    int32_t node = -1;       ///< glTF node index it came from (-1 for procedural)
};

/// A flattened primitive. A sphere or capsule is stored as its box and centre, {lo, hi, centre}
/// (its radius in Scene::curved_radius, a capsule's ends in Scene::capsule_ends), so every
/// builder that bounds primitives by their vertices bounds it right; builders that clip
/// triangles against planes refuse scenes with curved primitives.
struct Triangle {
    Vec3 v0, v1, v2;
};
inline Vec3 sphere_centre(const Triangle& t) { return t.v2; }
/// Length of the longest column of the transform's linear part: the factor a curved primitive's
/// radius scales by (a sphere under a non-uniform scale becomes the sphere bounding the ellipsoid).
double largest_axis_scale(const glm::dmat4& m);
/// A curved primitive in world space: a sphere (a == b, r0 == r1) or a capsule from a (radius r0)
/// to b (radius r1).
struct CurvedShape {
    Vec3 a, b;
    float r0 = 0.0f, r1 = 0.0f;
    bool capsule() const { return a != b; }
};
/// Curved primitive `prim` of `mesh` as an instance places it: its ends already in world space
/// (`a`, `b`), its radii scaled by the transform's largest axis (`scale`, largest_axis_scale);
/// a capsule of zero length is the larger of its end spheres. flatten() and
/// Scene::curved_shape() both take it from here.
CurvedShape placed_curved_shape(const Mesh& mesh, size_t prim, const Vec3& a, const Vec3& b, double scale);
struct Scene;
/// Surface area of curved primitive `prim`: a sphere's 4 pi r^2, a capsule's 2 pi r L + 4 pi r^2
/// (with two radii, its cone's band and the two end spheres' caps beyond it).
double curved_area(const Scene& scene, uint32_t prim);

/// Peak memory of tracing, per flattened triangle (scene, BVH build, hardware image, writer),
/// measured with /usr/bin/time on 2M-triangle hairballs (docs/validation.md).
constexpr uint64_t kBytesPerFlatTriangle = 200;
/// Most triangles a scene may flatten to: primitive ids are int32, and the estimate at
/// kBytesPerFlatTriangle must fit this machine's physical memory.
uint64_t max_flat_triangles();
/// Throws rtsim::Error "<source>: <what> flattens to N triangles (about X GiB to trace); ..."
/// when `triangles` exceeds max_flat_triangles(). Called before any flattening is allocated.
void check_flat_size(const std::string& source, uint64_t triangles, const std::string& what);

struct Scene;
/// Refuses (rtsim::Error naming the file and the glTF node) an instance whose transform is not
/// finite, and a scene whose every triangle collapses to zero area in world space (a node scaled
/// by 0 or 1e-30, a matrix of zeros: no ray could hit anything). `invertible`: every transform
/// must also invert in single precision (two-level structures trace rays in object space).
/// Refuses too, when `invertible`, an instance of spheres or capsules whose transform is not a
/// similarity (is_similarity).
void check_instance_transforms(const Scene& scene, bool invertible);
/// Refuses (naming the node, and `when`, e.g. " in frame 3") instance `instance` of a mesh of
/// spheres or capsules placed by `m` when `m` is not a similarity.
void check_curved_similarity(const Scene& scene, size_t instance, const glm::dmat4& m, const std::string& when);
/// True if the transform's linear part is a rotation (or reflection) times a uniform scale, to a
/// relative 1e-5: a sphere stays a sphere under it.
bool is_similarity(const glm::dmat4& m);

struct Scene {
    std::string source;  ///< file the scene was read from
    std::vector<Mesh> meshes;
    std::vector<Instance> instances;
    std::vector<Material> materials;  ///< never empty: a default material is appended if needed
    std::vector<Light> lights;
    std::vector<Camera> cameras;
    std::vector<std::string> warnings;  ///< non-fatal oddities (ignored extensions, ...)
    /// Meshes that deform over frames (skins, morph targets, procedural motion), or null.
    std::shared_ptr<const MeshAnimation> animation;

    // Flattened world space, indexed by primitive id (filled by flatten()).
    std::vector<Triangle> triangles;
    std::vector<uint32_t> tri_material;
    std::vector<uint32_t> tri_instance;
    /// Per primitive: a sphere's or capsule's world-space radius, 0 for a triangle; empty when
    /// the scene has no curved primitives (filled by flatten()).
    std::vector<float> curved_radius;
    /// Per primitive: a capsule's world-space radius at its second end (curved_radius is its
    /// first end's); empty when no capsule has two radii (filled by flatten()).
    std::vector<float> curved_end_radius;
    float end_radius(uint32_t prim) const { return curved_end_radius.empty() ? curved_radius[prim] : curved_end_radius[prim]; }
    /// Per primitive: a capsule's two ends in world space (a sphere's or triangle's are its
    /// centre, twice); empty when the scene has no capsules (filled by flatten()).
    std::vector<std::array<Vec3, 2>> capsule_ends;
    uint64_t placed_triangles = 0;  ///< set by index_instances() (flatten() fills triangles instead)
    /// Some mesh holds curved primitives (set by index_instances()): a scene kept as instances
    /// looks a primitive up in its mesh only then (is_curved() is on every hit's path).
    bool curved_meshes = false;
    Aabb bounds;

    /// Fills triangles/tri_material/tri_instance/bounds from meshes and instances. Vertices are
    /// transformed in double precision and rounded once to float. Throws rtsim::Error naming
    /// `source` if the result would not fit (check_flat_size) or a vertex is not finite.
    void flatten();
    /// Instead of flatten(), for two-level tracing (docs/accel.md, "Two-level structures"):
    /// assigns each instance's prim_base and the world bounds (the meshes' boxes under each
    /// instance's transform) without a world-space triangle list; placed_triangles counts the
    /// triangles. Throws rtsim::Error naming `source` if primitive ids would not fit int32.
    void index_instances();
    bool flattened() const { return !triangles.empty(); }
    /// Flattened or kept as instances (then looked up in the placing mesh, as world_triangle()).
    bool is_curved(uint32_t prim) const {
        return flattened() ? !curved_radius.empty() && curved_radius[prim] > 0.0f
                           : curved_meshes && placed_is_curved(prim, false);
    }
    bool is_capsule(uint32_t prim) const {
        return flattened() ? is_curved(prim) && !capsule_ends.empty() && capsule_ends[prim][0] != capsule_ends[prim][1]
                           : curved_meshes && placed_is_curved(prim, true);
    }
    bool is_sphere(uint32_t prim) const { return is_curved(prim) && !is_capsule(prim); }
    /// Spheres and capsules among the flattened primitives.
    size_t sphere_count() const;
    size_t capsule_count() const;
    /// True if some mesh has curved primitives, and capsules (flattened or not).
    bool has_curved() const;
    bool has_capsules() const;
    /// World-space curved primitive `prim` (is_curved): the flattened one, or computed as
    /// flatten() computes it (ends transformed, radii scaled by the transform's largest axis).
    CurvedShape curved_shape(uint32_t prim) const;
    /// Triangles the instances place: the flattened list's size, or placed_triangles.
    size_t triangle_count() const { return flattened() ? triangles.size() : size_t(placed_triangles); }
    /// Instance that places primitive `prim` (binary search over prim_base).
    uint32_t instance_of(uint32_t prim) const;
    /// World-space triangle `prim`: the flattened one, or computed as flatten() computes it.
    Triangle world_triangle(uint32_t prim) const;
    /// Material of primitive `prim`, flattened or not.
    uint32_t material_of(uint32_t prim) const;
    /// True if some mesh is placed more than once (shared meshes or GPU instancing).
    bool uses_instancing() const;
    /// Index of the default material (white, rough dielectric) appended on demand.
    uint32_t default_material();

private:
    /// is_curved() (capsule: is_capsule()) of a primitive of a scene kept as instances.
    bool placed_is_curved(uint32_t prim, bool capsule) const;
};

}  // namespace rtsim
