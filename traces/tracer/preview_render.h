#pragma once
// A simple preview image of the traced frame: base colour lit by the lights the shadow rays
// found unoccluded (a headlight when the scene has no lights), mirrors showing what their
// reflection ray hit, emissive surfaces glowing, a sky gradient for misses. For checking a
// trace by eye, not a physically based render.
#include <cstdint>
#include <string>
#include <vector>

#include "traces/raygen/secondary.h"
#include "traces/scene/scene.h"

namespace rtsim {

class PreviewRender {
public:
    PreviewRender(uint32_t width, uint32_t height, uint32_t light_count);
    /// Accumulates a traced wavefront (only rays descending directly from primary rays count).
    void add(const Scene& scene, const std::vector<PendingRay>& rays, const std::vector<Hit>& hits);
    /// Writes an 8-bit sRGB PNG; throws rtsim::Error if the file cannot be written.
    void write_png(const std::string& path) const;

private:
    struct Pixel {
        Vec3 albedo{0.0f};
        Vec3 emissive{0.0f};
        Vec3 sky{0.0f};
        Vec3 reflected{0.0f};
        float headlight = 0.0f;
        float light = 0.0f;
        float metallic = 0.0f;
        bool hit = false;
        bool has_reflection = false;
    };
    uint32_t m_width, m_height, m_light_count;
    std::vector<Pixel> m_pixels;
};

}  // namespace rtsim
