#pragma once
// glTF skins and morph targets driven by the file's own animation channels (glTF 2.0 sections
// 3.7.3 skins, 3.7.2.2 morph targets, 3.11 animations) as Scene::animation. Internal to
// traces/scene: include only from traces/scene/*.cpp.
#include <memory>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "traces/scene/gltf_internal.h"

namespace rtsim::gltf {

/// One animation channel's sampler, read and checked (times finite and non-decreasing, values
/// finite, counts matching the interpolation).
struct Sampler {
    enum class Interpolation : uint8_t { linear = 0, step = 1, cubic_spline = 2 };
    Interpolation interpolation = Interpolation::linear;
    std::vector<float> times;   ///< seconds, one per keyframe
    std::vector<float> values;  ///< width per keyframe (CUBICSPLINE: in-tangent, value, out-tangent)
    int width = 0;              ///< floats per value: 3 translation/scale, 4 rotation, targets weights

    /// The value at `t` seconds (clamped to the first and last keyframes) into out[0..width).
    /// `rotation`: LINEAR slerps, and every result is normalised.
    void sample(double t, bool rotation, float* out) const;
};

/// A node property an animation drives.
struct Channel {
    enum class Path : uint8_t { translation = 0, rotation = 1, scale = 2, weights = 3 };
    int node = -1;
    Path path = Path::translation;
    Sampler sampler;
};

/// Every channel of every animation in the model (all play together, as one clip; a file with
/// several clips plays them at once). Throws rtsim::Error naming the file and the animation,
/// channel or sampler index on bad input.
std::vector<Channel> read_channels(const Source& src);

/// Scene::animation for the skinned and morphed meshes of the model, or null when none deforms.
/// `mesh_of`: glTF mesh index -> Scene::meshes index (-1 when not placed).
std::shared_ptr<const MeshAnimation> read_gltf_animation(const Source& src,
                                                         const std::vector<int>& mesh_of,
                                                         const Scene& scene);

}  // namespace rtsim::gltf
