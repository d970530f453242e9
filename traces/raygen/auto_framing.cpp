#include "traces/raygen/auto_framing.h"

#include "traces/raygen/surface.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "traces/accel/accel.h"
#include "traces/common/error.h"
#include "traces/raygen/camera.h"
#include "traces/raygen/surface.h"

namespace rtsim {

namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float kFovDegrees = 60.0f;

/// Centre of a box without overflow (lo + hi may exceed the float range where hi - lo does not).
Vec3 mid(const Aabb& b) { return b.lo + 0.5f * (b.hi - b.lo); }

/// Directions spread evenly over the sphere (Fibonacci lattice).
std::vector<Vec3> sphere_directions(int n) {
    std::vector<Vec3> dirs;
    for (int i = 0; i < n; ++i) {
        float z = 1.0f - 2.0f * (float(i) + 0.5f) / float(n);
        float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
        float phi = float(i) * kPi * (3.0f - std::sqrt(5.0f));
        dirs.emplace_back(r * std::cos(phi), z, r * std::sin(phi));
    }
    return dirs;
}

/// Negative when the ray meets the hit's front face (a triangle's by its winding, a curved primitive's
/// outside), positive at a back face, 0 for a triangle seen edge-on.
float facing(const Scene& scene, const Ray& r, const Hit& h) {
    if (scene.is_curved(uint32_t(h.prim))) return surface_point(scene, r, h).front ? -1.0f : 1.0f;
    const Triangle t = scene.world_triangle(uint32_t(h.prim));
    return glm::dot(glm::cross(t.v1 - t.v0, t.v2 - t.v0), r.direction);
}

/// Fraction of probe rays from p that hit the front face of some geometry. A room seen from
/// inside shows its front faces; a closed object probed from its centre shows back faces.
float enclosure(const Scene& scene, const Accel& accel, const Vec3& p) {
    std::vector<Vec3> dirs = sphere_directions(128);
    int front = 0;
    for (const Vec3& d : dirs) {
        const Ray probe{p, 0.0f, d, INFINITY};
        Hit h = accel.trace(probe, TraversalMode::closest_hit);
        if (!h.valid()) continue;
        front += facing(scene, probe, h) < 0.0f;
    }
    return float(front) / float(dirs.size());
}

/// How good a view from eye along forward is: median free distance over a cone of probes,
/// zero if the eye sits inside a solid (probes hit back faces).
float view_score(const Scene& scene, const Accel& accel, const Vec3& eye, const Vec3& target) {
    PinholeCamera cam = make_camera(look_at(eye, target, kFovDegrees), 16, 9);
    std::vector<float> dist;
    int back_faces = 0;
    for (uint32_t y = 0; y < 9; ++y)
        for (uint32_t x = 0; x < 16; ++x) {
            Ray r = primary_ray(cam, x, y, 16, 9);
            Hit h = accel.trace(r, TraversalMode::closest_hit);
            if (!h.valid()) {
                dist.push_back(1e30f);
                continue;
            }
            if (facing(scene, r, h) > 0.0f) ++back_faces;
            dist.push_back(h.t);
        }
    if (back_faces > int(dist.size()) / 2) return 0.0f;
    std::nth_element(dist.begin(), dist.begin() + dist.size() / 2, dist.end());
    return dist[dist.size() / 2];
}

Camera frame_interior(const Scene& scene, const Accel& accel, std::ostringstream& why) {
    const Aabb& b = scene.bounds;
    Vec3 e = b.extent();
    int axis = e.x >= e.z ? 0 : 2;  // longest horizontal axis (glTF: +Y up)
    Camera best;
    float best_score = -1.0f;
    // Candidate eyes along the long axis at a few heights, looking towards the far end.
    for (float along : {0.1f, 0.2f, 0.3f}) {
        for (float height : {0.2f, 0.3f, 0.45f}) {
            Vec3 eye = mid(b);
            eye[axis] = b.lo[axis] + along * e[axis];
            eye.y = b.lo.y + height * e.y;
            Vec3 target = eye;
            target[axis] = b.hi[axis];
            target.y = b.lo.y + 0.35f * e.y;
            float score = view_score(scene, accel, eye, target);
            if (score > best_score) {
                best_score = score;
                best = look_at(eye, target, kFovDegrees);
            }
        }
    }
    why << "interior (probes from the centre see front faces), eye inside looking along the "
        << (axis == 0 ? "x" : "z") << " axis";
    return best;
}

/// Three-quarter view from outside, at the smallest distance where all 8 box corners project
/// inside the image (with a 5% margin). In double precision: the box may span or sit near the
/// float range (1e20 wide, or 1e30 from the origin) where float sums lose the offset.
Camera frame_object(const Scene& scene, float aspect) {
    const Aabb& b = scene.bounds;
    const glm::dvec3 lo(b.lo), hi(b.hi), center = (lo + hi) * 0.5;
    const glm::dvec3 dir = glm::normalize(glm::dvec3(0.6, 0.45, 1.0));
    // The orientation does not depend on where the box is: take it from a camera at the origin.
    PinholeCamera cam = make_camera(look_at(Vec3(dir), Vec3(0.0f), kFovDegrees), 4, 3);
    const glm::dvec3 fwd(cam.forward), right(cam.right), up(cam.up);
    const double tan_y = cam.tan_half_fov, tan_x = double(cam.tan_half_fov) * aspect;
    double dist = 0.0;
    for (int i = 0; i < 8; ++i) {
        glm::dvec3 corner((i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z);
        glm::dvec3 p = corner - center;
        double depth = glm::dot(p, fwd);
        dist = std::max(dist, std::abs(glm::dot(p, right)) / tan_x - depth);
        dist = std::max(dist, std::abs(glm::dot(p, up)) / tan_y - depth);
    }
    dist = std::max(dist * 1.05, 1e-6 * glm::length(hi - lo));
    const glm::dvec3 eye = center + dir * dist;
    const Vec3 eye_f(eye), center_f(center);
    const bool representable = std::isfinite(eye_f.x) && std::isfinite(eye_f.y) && std::isfinite(eye_f.z) &&
                               std::isfinite(center_f.x) && std::isfinite(center_f.y) &&
                               std::isfinite(center_f.z) && eye_f != center_f;
    if (!representable) {
        std::ostringstream os;
        os << scene.source << ": automatic framing failed: the scene's bounds [" << lo.x << ", " << lo.y << ", "
           << lo.z << "] .. [" << hi.x << ", " << hi.y << ", " << hi.z << "] need an eye at distance " << dist
           << " from their centre, which single-precision rays cannot represent; scale the scene or give a "
              "camera (--camera)";
        throw Error(os.str());
    }
    return look_at(eye_f, center_f, kFovDegrees);
}

}  // namespace

Camera auto_frame(const Scene& scene, const Accel& accel, float aspect, std::string* why) {
    std::ostringstream reason;
    reason << "automatic framing: ";
    const Aabb& b = scene.bounds;
    const Vec3 e = b.extent();
    if (b.empty() || !(e.x > 0.0f || e.y > 0.0f || e.z > 0.0f) || !std::isfinite(e.x + e.y + e.z)) {
        std::ostringstream os;
        os << scene.source << ": automatic framing failed: the scene's bounds [" << b.lo.x << ", " << b.lo.y
           << ", " << b.lo.z << "] .. [" << b.hi.x << ", " << b.hi.y << ", " << b.hi.z << "] "
           << (b.empty() ? "are empty" : std::isfinite(e.x + e.y + e.z) ? "have zero extent (every triangle is one point)"
                                                                        : "exceed the float range")
           << "; give a camera (--camera)";
        throw Error(os.str());
    }
    float enclosed = enclosure(scene, accel, b.center());
    Camera cam;
    if (enclosed >= 0.6f) {
        cam = frame_interior(scene, accel, reason);
    } else {
        cam = frame_object(scene, aspect);
        reason << "object seen from outside";
    }
    cam.name = "auto";
    reason << " (enclosure " << int(enclosed * 100.0f + 0.5f) << "%)";
    if (why) *why = reason.str();
    return cam;
}

}  // namespace rtsim
