#pragma once
// The documented motion of animated frames (docs/accel.md, "Frames"): `rtsim trace --frames N`
// traces an instanced scene N times, frame f with every *shared* instance (one whose geometry is
// placed more than once) moved from its rest transform M as
//
//   M(f) = T(c + (0, bob, 0)) * R_y(spin) * T(-c) * M
//   spin = s * f * 2 pi / 32              (11.25 degrees a frame; s = +1 for even instance ids, -1 for odd)
//   bob  = 0.05 h (sin(2 pi f / 16 + phi) - sin(phi)),   phi = 2 pi frac(0.6180339887 i)
//
// where i is the instance id (scene order), c the centre and h the height (y extent) of the
// instance's world box at rest. Frame 0 is the rest pose exactly (M(0) = M); instances placed
// once (a ground, a building) never move. Deterministic: doubles throughout, no randomness.
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "traces/scene/scene.h"

namespace rtsim {

/// Every instance's rest transform and whether it moves (shared geometry), taken once.
struct SceneMotion {
    std::vector<glm::dmat4> rest;
    std::vector<bool> moves;
    std::vector<glm::dvec3> centre;  ///< world box centre at rest
    std::vector<double> height;      ///< world box height at rest
};

/// The motion of `scene` (kept as instances, not flattened); `moving_mesh[m]` says whether
/// instances of mesh m move (two_level.h: geometry placed more than once).
SceneMotion scene_motion(const Scene& scene, const std::vector<bool>& moving_mesh);

/// The transform of instance `i` in frame `frame` (the formula above).
glm::dmat4 animated_transform(const SceneMotion& motion, uint32_t i, uint32_t frame);

/// Poses the scene's instances for `frame` and re-indexes it (world bounds; primitive ids are
/// unchanged), so shading and secondary rays see the moved instances.
void pose_scene(Scene& scene, const SceneMotion& motion, uint32_t frame);

/// One line naming the motion, for the manifest.
const char* motion_description();

}  // namespace rtsim
