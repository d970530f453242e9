#pragma once
// Geometry that deforms over frames (docs/accel.md, "Moving scenes"): a scene's meshes whose
// object-space vertices change from frame to frame — glTF skins and morph targets driven by the
// file's own animation channels, or a procedural scene's motion (a waving cloth, an exploding
// hairball). The tracer asks it for each deforming mesh's positions per frame and builds (or
// refits) that mesh's BLAS from them (traces/tracer/frames.h, --frame-policy).
//
// Contract: triangle count, order and materials never change; frame 0 may differ from the rest
// positions in Mesh::positions (a skin's bind pose is not its first animated pose). pose() is
// deterministic (same frame, same bits) and returns finite positions.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "traces/common/aabb.h"

namespace rtsim {

class MeshAnimation {
public:
    virtual ~MeshAnimation() = default;
    /// True if mesh `mesh` (index into Scene::meshes) changes shape over frames.
    virtual bool deforms(uint32_t mesh) const = 0;
    /// Object-space positions of mesh `mesh` at frame `frame` (3 per triangle, like
    /// Mesh::positions), written to `out` (resized). Frames are 1 / frames_per_second apart.
    virtual void pose(uint32_t mesh, uint32_t frame, std::vector<Vec3>* out) const = 0;
    /// One line naming the motion, for the trace manifest.
    virtual std::string description() const = 0;
    /// Frames per second the animation is sampled at (glTF channels are in seconds).
    virtual double frames_per_second() const { return 60.0; }
};

}  // namespace rtsim
