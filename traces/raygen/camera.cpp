#include "traces/raygen/camera.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "traces/common/error.h"

namespace rtsim {

PinholeCamera make_camera(const Camera& camera, uint32_t width, uint32_t height) {
    PinholeCamera c;
    c.eye = camera.eye;
    c.forward = glm::normalize(camera.forward);
    c.right = glm::normalize(glm::cross(c.forward, camera.up));
    c.up = glm::cross(c.right, c.forward);
    c.tan_half_fov = std::tan(camera.yfov * 0.5f);
    c.aspect = camera.aspect > 0.0f ? camera.aspect : float(width) / float(height);
    return c;
}

Camera look_at(const Vec3& eye, const Vec3& target, float yfov_degrees) {
    Camera c;
    c.name = "look_at";
    c.eye = eye;
    // In double: target - eye may be beyond 1e19, whose float square overflows.
    c.forward = Vec3(glm::normalize(glm::dvec3(target) - glm::dvec3(eye)));
    Vec3 up(0.0f, 1.0f, 0.0f);
    if (std::abs(glm::dot(up, c.forward)) > 0.999f) up = Vec3(0.0f, 0.0f, 1.0f);
    c.up = glm::normalize(glm::cross(glm::cross(c.forward, up), c.forward));
    c.yfov = yfov_degrees * 3.14159265358979f / 180.0f;
    return c;
}

void check_camera(const PinholeCamera& c, const std::string& source) {
    auto finite = [](const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
    auto unit = [&finite](const Vec3& v) { return finite(v) && std::abs(glm::length(v) - 1.0f) < 1e-3f; };
    auto text = [](const Vec3& v) {
        return "(" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) + ")";
    };
    if (!finite(c.eye)) throw Error(source + ": camera eye " + text(c.eye) + " is not finite in single precision");
    if (!unit(c.forward) || !unit(c.right) || !unit(c.up))
        throw Error(source + ": camera has no valid view direction (forward " + text(c.forward) + ", up " +
                    text(c.up) + "): eye equal to target, or NaN");
    if (!(c.tan_half_fov > 0.0f && std::isfinite(c.tan_half_fov)))
        throw Error(source + ": camera field of view must be in (0, 180) degrees");
    if (!(c.aspect > 0.0f && std::isfinite(c.aspect)))
        throw Error(source + ": camera aspect ratio " + std::to_string(c.aspect) + " is not a positive number");
}

void check_scene_reach(const PinholeCamera& c, const Aabb& b, const std::string& source) {
    const glm::dvec3 eye(c.eye), lo(b.lo), hi(b.hi);
    double reach = 0.0;
    for (int a = 0; a < 3; ++a)
        reach = std::max({reach, std::abs(lo[a] - eye[a]), std::abs(hi[a] - eye[a]), hi[a] - lo[a]});
    if (reach <= kMaxRayReach) return;
    char text[200];
    std::snprintf(text, sizeof text, "the scene reaches %.3g from the camera eye (%.3g, %.3g, %.3g) on some axis", reach,
                  eye.x, eye.y, eye.z);
    throw Error(source + ": " + text +
                "; single-precision ray/triangle tests overflow beyond about 1e19 and every ray would miss "
                "(limit 1e18): scale or recentre the scene, or move the camera");
}

Ray primary_ray(const PinholeCamera& c, uint32_t x, uint32_t y, uint32_t width, uint32_t height) {
    // Pixel centre in normalised device coordinates, y pointing down the image.
    float sx = (2.0f * (float(x) + 0.5f) / float(width) - 1.0f) * c.tan_half_fov * c.aspect;
    float sy = (1.0f - 2.0f * (float(y) + 0.5f) / float(height)) * c.tan_half_fov;
    Ray ray;
    ray.origin = c.eye;
    ray.direction = glm::normalize(c.forward + sx * c.right + sy * c.up);
    ray.tmin = 0.0f;
    ray.tmax = std::numeric_limits<float>::infinity();
    return ray;
}

}  // namespace rtsim
