#pragma once
// Pinhole camera rays, one through the centre of each pixel (row-major, y down).
#include <cstdint>
#include <string>

#include "traces/common/aabb.h"
#include "traces/common/ray.h"
#include "traces/scene/scene.h"

namespace rtsim {

struct PinholeCamera {
    Vec3 eye{0.0f};
    Vec3 forward{0.0f, 0.0f, -1.0f};
    Vec3 right{1.0f, 0.0f, 0.0f};
    Vec3 up{0.0f, 1.0f, 0.0f};
    float tan_half_fov = 0.5f;  ///< tan(yfov / 2)
    float aspect = 1.0f;        ///< width / height
};

/// From a scene camera; aspect comes from the camera or, if 0, from the image.
PinholeCamera make_camera(const Camera& camera, uint32_t width, uint32_t height);
/// Looking from eye at target with a vertical field of view in degrees (+Y up, unless looking
/// straight up or down, then +Z).
Camera look_at(const Vec3& eye, const Vec3& target, float yfov_degrees);

/// Throws rtsim::Error "<source>: ..." unless the camera makes valid rays: finite eye, finite
/// unit forward/right/up axes, a field of view in (0, 180) degrees, a finite positive aspect.
void check_camera(const PinholeCamera& camera, const std::string& source);

/// Largest distance between a ray origin and the geometry that the single-precision watertight
/// ray/triangle test handles: it multiplies two origin-relative coordinates (Woop, Benthin &
/// Wald 2013), which overflows float beyond about 1.3e19. A margin of 10x is kept.
constexpr double kMaxRayReach = 1e18;

/// Throws rtsim::Error "<source>: ..." when some corner of `bounds` lies farther than
/// kMaxRayReach from the camera's eye on some axis, or the bounds are that wide: every ray
/// would silently miss.
void check_scene_reach(const PinholeCamera& camera, const Aabb& bounds, const std::string& source);

/// Primary ray through pixel (x, y); direction normalised, tmin 0, tmax +inf.
Ray primary_ray(const PinholeCamera& camera, uint32_t x, uint32_t y, uint32_t width, uint32_t height);

}  // namespace rtsim
