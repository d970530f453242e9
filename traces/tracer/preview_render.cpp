#include "traces/tracer/preview_render.h"

#include <algorithm>
#include <cmath>

#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image_write.h>

#include "traces/common/error.h"

#include "traces/raygen/surface.h"

namespace rtsim {

namespace {

Vec3 sky(const Vec3& d) {
    float t = 0.5f * (glm::normalize(d).y + 1.0f);
    return (1.0f - t) * Vec3(0.9f, 0.9f, 0.95f) + t * Vec3(0.45f, 0.6f, 0.9f);
}

float headlight(const Scene& scene, const Ray& ray, const Hit& hit) {
    if (scene.is_curved(uint32_t(hit.prim))) {
        const float len = glm::length(ray.direction);
        return len > 0.0f ? std::abs(glm::dot(surface_point(scene, ray, hit).normal, ray.direction)) / len : 0.0f;
    }
    const Triangle t = scene.world_triangle(uint32_t(hit.prim));
    Vec3 n = glm::cross(t.v1 - t.v0, t.v2 - t.v0);
    float len = glm::length(n) * glm::length(ray.direction);
    return len > 0.0f ? std::abs(glm::dot(n, ray.direction)) / len : 0.0f;
}

uint8_t to_srgb8(float linear) {
    float c = std::clamp(linear, 0.0f, 1.0f);
    c = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
    return uint8_t(std::lround(c * 255.0f));
}

}  // namespace

PreviewRender::PreviewRender(uint32_t width, uint32_t height, uint32_t light_count)
    : m_width(width), m_height(height), m_light_count(light_count), m_pixels(size_t(width) * height) {}

void PreviewRender::add(const Scene& scene, const std::vector<PendingRay>& rays, const std::vector<Hit>& hits) {
    for (size_t i = 0; i < rays.size(); ++i) {
        const PendingRay& r = rays[i];
        Pixel& px = m_pixels[r.pixel];
        const Hit& h = hits[i];
        if (r.kind == RayKind::primary) {
            px.sky = sky(r.ray.direction);
            if (!h.valid()) continue;
            const Material& m = scene.materials[scene.material_of(uint32_t(h.prim))];
            px.hit = true;
            px.albedo = Vec3(m.base_color);
            px.emissive = m.emissive;
            px.metallic = m.metallic;
            px.headlight = headlight(scene, r.ray, h);
        } else if (r.depth == 1 && r.kind == RayKind::shadow) {
            if (!h.valid()) px.light += r.shade / float(std::max(1u, m_light_count));
        } else if (r.depth == 1 && r.kind == RayKind::reflection) {
            px.has_reflection = true;
            if (h.valid()) {
                const Material& m = scene.materials[scene.material_of(uint32_t(h.prim))];
                px.reflected = Vec3(m.base_color) * (0.3f + 0.7f * headlight(scene, r.ray, h)) + m.emissive;
            } else {
                px.reflected = sky(r.ray.direction);
            }
        }
    }
}

void PreviewRender::write_png(const std::string& path) const {
    std::vector<uint8_t> rgb(size_t(m_width) * m_height * 3);
    for (size_t i = 0; i < m_pixels.size(); ++i) {
        const Pixel& px = m_pixels[i];
        Vec3 c = px.sky;
        if (px.hit) {
            float lit = m_light_count ? 0.25f * px.headlight + 0.9f * px.light : px.headlight;
            // Exposure: albedos in these scenes are dark (texture means), so lift them.
            c = px.albedo * lit * 1.6f + px.emissive;
            if (px.has_reflection) c = glm::mix(c, px.reflected, std::clamp(px.metallic, 0.3f, 0.8f));
        }
        for (int k = 0; k < 3; ++k) rgb[3 * i + k] = to_srgb8(c[k]);
    }
    if (!stbi_write_png(path.c_str(), int(m_width), int(m_height), 3, rgb.data(), int(m_width) * 3))
        throw Error(path + ": cannot write PNG");
}

}  // namespace rtsim
