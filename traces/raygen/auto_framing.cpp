#include "traces/raygen/auto_framing.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "traces/accel/accel.h"
#include "traces/raygen/camera.h"

namespace rtsim {

namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float kFovDegrees = 60.0f;

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

/// Fraction of probe rays from p that hit the front face of some geometry. A room seen from
/// inside shows its front faces; a closed object probed from its centre shows back faces.
float enclosure(const Scene& scene, const Accel& accel, const Vec3& p) {
    std::vector<Vec3> dirs = sphere_directions(128);
    int front = 0;
    for (const Vec3& d : dirs) {
        Hit h = accel.trace(Ray{p, 0.0f, d, INFINITY}, TraversalMode::closest_hit);
        if (!h.valid()) continue;
        const Triangle& t = scene.triangles[h.prim];
        front += glm::dot(glm::cross(t.v1 - t.v0, t.v2 - t.v0), d) < 0.0f;
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
            const Triangle& t = scene.triangles[h.prim];
            if (glm::dot(glm::cross(t.v1 - t.v0, t.v2 - t.v0), r.direction) > 0.0f) ++back_faces;
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
            Vec3 eye = b.center();
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
/// inside the image (with a 5% margin).
Camera frame_object(const Aabb& b, float aspect) {
    Vec3 dir = glm::normalize(Vec3(0.6f, 0.45f, 1.0f));
    Camera probe = look_at(b.center() + dir, b.center(), kFovDegrees);
    PinholeCamera cam = make_camera(probe, 4, 3);
    float tan_y = cam.tan_half_fov, tan_x = cam.tan_half_fov * aspect;
    float dist = 0.0f;
    for (int i = 0; i < 8; ++i) {
        Vec3 corner((i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y, (i & 4) ? b.hi.z : b.lo.z);
        Vec3 p = corner - b.center();
        float depth = glm::dot(p, cam.forward);
        dist = std::max(dist, std::abs(glm::dot(p, cam.right)) / tan_x - depth);
        dist = std::max(dist, std::abs(glm::dot(p, cam.up)) / tan_y - depth);
    }
    dist = std::max(dist * 1.05f, 1e-6f * glm::length(b.extent()));
    return look_at(b.center() + dir * dist, b.center(), kFovDegrees);
}

}  // namespace

Camera auto_frame(const Scene& scene, const Accel& accel, float aspect, std::string* why) {
    std::ostringstream reason;
    reason << "automatic framing: ";
    const Aabb& b = scene.bounds;
    float enclosed = enclosure(scene, accel, b.center());
    Camera cam;
    if (enclosed >= 0.6f) {
        cam = frame_interior(scene, accel, reason);
    } else {
        cam = frame_object(b, aspect);
        reason << "object seen from outside";
    }
    cam.name = "auto";
    reason << " (enclosure " << int(enclosed * 100.0f + 0.5f) << "%)";
    if (why) *why = reason.str();
    return cam;
}

}  // namespace rtsim
