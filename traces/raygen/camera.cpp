#include "traces/raygen/camera.h"

#include <cmath>

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
    c.forward = glm::normalize(target - eye);
    Vec3 up(0.0f, 1.0f, 0.0f);
    if (std::abs(glm::dot(up, c.forward)) > 0.999f) up = Vec3(0.0f, 0.0f, 1.0f);
    c.up = glm::normalize(glm::cross(glm::cross(c.forward, up), c.forward));
    c.yfov = yfov_degrees * 3.14159265358979f / 180.0f;
    return c;
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
