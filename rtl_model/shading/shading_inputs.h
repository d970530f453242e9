#pragma once
// What the shading block reads of a trace (docs/shading.md): the material, texture and
// per-primitive tables, each ray's record and shading record, and the reference texel addresses
// its fetches are checked against. Filled by the harness from a version-5 trace's shading sections.
#include <cstdint>
#include <vector>

#include "traces/format/trace_format.h"

namespace rtsim {

struct ShadingInputs {
    std::vector<MaterialRecord> materials;
    std::vector<TextureRecord> textures;  ///< empty: no material samples a texture (no texture model)
    std::vector<TriShadeRecord> tris;     ///< indexed by primitive id
    std::vector<RayRecord> rays;          ///< indexed by ray id
    std::vector<ShadeRecord> shade;       ///< indexed by ray id
    std::vector<uint64_t> reference_fetches;  ///< TXFT
    /// Rays per wavefront, in trace order (a trace lists its rays depth by depth).
    std::vector<uint64_t> wavefronts;
    /// An animated trace: each frame's first ray and rays (empty: one frame of every ray), and
    /// the frame of each wavefront (wavefronts never span two frames).
    std::vector<FrameRecord> frames;
    std::vector<uint32_t> wavefront_frame;
    uint32_t shaders = 0;  ///< distinct hit shaders (MaterialRecord::shader < shaders)

    bool has_textures() const { return !textures.empty(); }
};

}  // namespace rtsim
