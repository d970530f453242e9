#pragma once
// Analytic motion of the procedural deforming scenes ("cloth", "exploding_hairball"). The writer
// stores a ProceduralMotion in the glTF mesh's extras.rtsimMotion, and the loader turns every such
// mesh into a deforming mesh of Scene::animation, so the scenes take the glTF path like the rest.
// Internal to traces/scene.
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "traces/scene/mesh_animation.h"

namespace tinygltf {
class Value;
}

namespace rtsim {

struct Scene;

/// One mesh's motion, as a function of time t = frame / 60 s.
struct ProceduralMotion {
    enum class Kind : uint8_t {
        /// y += amplitude * sin(2 pi (x / wavelength - t / period)) * (x - x_pinned) / extent:
        /// a travelling sine wave along +x whose amplitude grows from the pinned edge.
        wave = 0,
        /// Each triangle moves rigidly along (centroid - center), at a speed drawn per triangle
        /// in [speed_min, speed_max] from (seed, triangle index).
        scatter = 1,
    };
    Kind kind = Kind::wave;
    float amplitude = 0.1f;   ///< wave: metres
    float wavelength = 1.0f;  ///< wave: metres
    float period = 1.0f;      ///< wave: seconds per crest passing a point
    float x_pinned = 0.0f;    ///< wave: x of the still edge (metres)
    float extent = 1.0f;      ///< wave: x distance over which the amplitude reaches `amplitude`
    Vec3 center{0.0f};        ///< scatter: the explosion's centre (object space)
    float speed_min = 0.1f;   ///< scatter: metres per second
    float speed_max = 1.0f;   ///< scatter: metres per second
    uint64_t seed = 1;        ///< scatter: per-triangle speed stream
};

/// A scatter about the object's origin: each triangle (or sphere, or capsule) moves away from it
/// at a speed in [speed_min, speed_max] m/s drawn from `seed`.
inline ProceduralMotion scatter_motion(float speed_min, float speed_max, uint64_t seed) {
    ProceduralMotion m;
    m.kind = ProceduralMotion::Kind::scatter;
    m.center = Vec3(0.0f);
    m.speed_min = speed_min;
    m.speed_max = speed_max;
    m.seed = seed;
    return m;
}

/// The motion as the glTF extras object the loader reads back (read_procedural_motion).
tinygltf::Value procedural_motion_to_value(const ProceduralMotion& motion);
/// Reads extras.rtsimMotion of a glTF mesh; false if `extras` has none. Throws rtsim::Error
/// naming `where` on a malformed or non-finite motion.
bool read_procedural_motion(const tinygltf::Value& extras, const std::string& where,
                            ProceduralMotion* out);

/// Scene::animation for procedural motions: (Scene::meshes index, motion) pairs, over the
/// meshes' rest positions (copied from `scene`).
std::shared_ptr<const MeshAnimation> make_procedural_animation(
    const Scene& scene, std::vector<std::pair<uint32_t, ProceduralMotion>> motions);

}  // namespace rtsim
