// Spheres and capsules against Embree 3's own (RTC_GEOMETRY_TYPE_SPHERE_POINT, and
// RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE with each segment's two radii: the cone touching both end
// spheres, and the spheres; robust mode): the particles, the furball (overlapping beads: many near-ties) and its capsules,
// traced by rtsim's BVHs and by Embree with the same rays. Hits must name the same sphere with t within 1e-4 relative; every disagreement
// must be a graze (the ray passes within 1e-4 of the hit sphere's radius of its centre, where
// float and double arithmetic may decide differently) or a tie (two spheres crossed within 1e-4
// relative t: rtsim takes the smaller id, Embree either). Any-hit rays must agree on occlusion
// but for grazes.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include <embree3/rtcore.h>
#include <gtest/gtest.h>

#include "embree_oracle.h"
#include "traces/accel/accel.h"
#include "traces/common/rng.h"
#include "traces/scene/gltf_loader.h"
#include "traces/scene/procedural.h"
#include "tests/cpp/process_temp_dir.h"

namespace rtsim {
namespace {

/// Embree's spheres of a flattened scene (its triangles are left out: the rays are aimed so the
/// comparison is about spheres; rtsim traces only spheres too, see sphere_only_scene).
class EmbreeSpheres {
public:
    explicit EmbreeSpheres(const Scene& scene) {
        m_device = rtcNewDevice("threads=1");
        m_scene = rtcNewScene(m_device);
        rtcSetSceneFlags(m_scene, RTC_SCENE_FLAG_ROBUST);
        const size_t n = scene.triangles.size();
        const bool capsules = scene.capsule_count() > 0;  // all capsules, or all spheres
        RTCGeometry g = rtcNewGeometry(m_device, capsules ? RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE
                                                          : RTC_GEOMETRY_TYPE_SPHERE_POINT);
        const size_t vertices = capsules ? 2 * n : n;
        auto* v = static_cast<float*>(
            rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), vertices));
        uint32_t* segment = capsules ? static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
                                           g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, sizeof(uint32_t), n))
                                     : nullptr;
        for (size_t i = 0; i < n; ++i) {
            const float r = scene.curved_radius[i], r_end = scene.end_radius(uint32_t(i));
            if (!capsules) {
                const Vec3 c = sphere_centre(scene.triangles[i]);
                v[4 * i] = c.x, v[4 * i + 1] = c.y, v[4 * i + 2] = c.z, v[4 * i + 3] = r;
                continue;
            }
            for (int e = 0; e < 2; ++e) {
                const Vec3 p = scene.capsule_ends[i][size_t(e)];
                float* out = v + 4 * (2 * i + size_t(e));
                out[0] = p.x, out[1] = p.y, out[2] = p.z, out[3] = e == 0 ? r : r_end;
            }
            segment[i] = uint32_t(2 * i);
        }
        rtcCommitGeometry(g);
        rtcAttachGeometry(m_scene, g);
        rtcReleaseGeometry(g);
        rtcCommitScene(m_scene);
    }
    ~EmbreeSpheres() {
        rtcReleaseScene(m_scene);
        rtcReleaseDevice(m_device);
    }
    Hit intersect(const Ray& r) const {
        RTCRayHit rh{};
        oracle::embree_ray(r, &rh.ray);
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        rtcIntersect1(m_scene, &ctx, &rh);
        Hit h;
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return h;
        h.prim = int32_t(rh.hit.primID);
        h.t = rh.ray.tfar;
        return h;
    }
    bool occluded(const Ray& r) const {
        RTCRay ray{};
        oracle::embree_ray(r, &ray);
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        rtcOccluded1(m_scene, &ctx, &ray);
        return ray.tfar < 0.0f;  // Embree sets tfar to -inf on occlusion
    }

private:
    RTCDevice m_device;
    RTCScene m_scene;
};

/// The scene's spheres, or its capsules when it has any (ids dense in scene order; triangles and
/// the other kind dropped).
Scene sphere_only_scene(const Scene& full) {
    Scene s;
    Mesh mesh;
    mesh.name = "curved";
    const bool capsules = full.capsule_count() > 0;
    for (uint32_t p = 0; p < full.triangles.size(); ++p) {
        if (capsules ? !full.is_capsule(p) : !full.is_sphere(p)) continue;
        const Vec3 a = capsules ? full.capsule_ends[p][0] : sphere_centre(full.triangles[p]);
        const Vec3 b = capsules ? full.capsule_ends[p][1] : a;
        mesh.positions.insert(mesh.positions.end(), {a, b, b});
        mesh.radii.push_back(full.curved_radius[p]);
        mesh.end_radii.push_back(full.end_radius(p));
    }
    mesh.materials.assign(mesh.radii.size(), 0u);
    s.meshes.push_back(mesh);
    s.instances.push_back(Instance{});
    s.materials = {Material{}};
    s.flatten();
    return s;
}

/// The ray passes within a relative 1e-4 of the hit primitive's radius of its surface (the
/// swept sphere's signed distance, |q - c(s)| - r(s) at its minimiser s = y + q k / sqrt(1 - k^2);
/// the closest approach by ternary search, the distance being convex): a graze.
bool grazes(const Scene& scene, const Ray& r, const Hit& h) {
    if (!h.valid()) return false;
    const uint32_t p = uint32_t(h.prim);
    const glm::dvec3 a(scene.is_capsule(p) ? scene.capsule_ends[p][0] : sphere_centre(scene.triangles[p]));
    const glm::dvec3 b(scene.is_capsule(p) ? scene.capsule_ends[p][1] : sphere_centre(scene.triangles[p]));
    const double r0 = scene.curved_radius[p], r1 = scene.end_radius(p);
    const glm::dvec3 o(r.origin), d = glm::normalize(glm::dvec3(r.direction));
    const double length = glm::length(b - a);
    const bool one_sphere = length <= std::fabs(r1 - r0);
    auto distance = [&](double t) {
        const glm::dvec3 q = o + t * d;
        if (one_sphere) return r1 > r0 ? glm::length(q - b) - r1 : glm::length(q - a) - r0;
        const glm::dvec3 axis = (b - a) / length;
        const double k = (r1 - r0) / length, y = glm::dot(q - a, axis), across = glm::length(q - a - y * axis);
        const double s = glm::clamp(y + across * k / std::sqrt(1.0 - k * k), 0.0, length);
        return glm::length(q - (a + s * axis)) - (r0 + k * s);
    };
    double lo = 0.0, hi = 1e4;
    for (int k = 0; k < 200; ++k) {
        const double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3;
        if (distance(m1) < distance(m2)) hi = m2;
        else lo = m1;
    }
    return std::fabs(distance(lo)) <= 1e-4 * std::max(r0, r1);
}

void compare(const std::string& name, const Scene& full, const char* kind) {
    const Scene scene = sphere_only_scene(full);
    AccelOptions o;
    o.kind = kind;
    const std::unique_ptr<Accel> accel = load_accel(build_accel(scene, o), name);
    const EmbreeSpheres embree(scene);
    Rng rng(9);
    const Vec3 lo = scene.bounds.lo, ext = scene.bounds.hi - scene.bounds.lo;
    auto point = [&](float margin) {
        return lo - margin * ext + (1.0f + 2.0f * margin) * Vec3(rng.next(), rng.next(), rng.next()) * ext;
    };
    int rays = 20000, hits = 0, graze = 0, tie = 0, other = 0, occlusion_graze = 0;
    for (int i = 0; i < rays; ++i) {
        Ray r;
        r.origin = point(0.5f);
        r.direction = point(0.0f) - r.origin;
        const Hit a = accel->trace(r, TraversalMode::closest_hit), b = embree.intersect(r);
        hits += a.valid();
        if (a.valid() && b.valid() && a.prim == b.prim) {
            EXPECT_NEAR(a.t, b.t, 1e-4f * std::max(1.0f, a.t)) << name << " ray " << i;
        } else if (a.valid() || b.valid()) {
            if (grazes(scene, r, a) || grazes(scene, r, b)) {
                ++graze;
            } else if (a.valid() && b.valid() && std::fabs(a.t - b.t) <= 1e-4f * a.t) {
                ++tie;
            } else {
                ++other;
                ADD_FAILURE() << name << " " << kind << " ray " << i << ": rtsim sphere " << a.prim << " t " << a.t
                              << "; Embree sphere " << b.prim << " t " << b.t;
            }
        }
        Ray shadow = r;
        shadow.tmax = 0.5f;  // halfway to the target: some occluded, some not
        const bool ours = accel->trace(shadow, TraversalMode::any_hit).valid(), theirs = embree.occluded(shadow);
        if (ours != theirs) {
            const Hit near = accel->trace(shadow, TraversalMode::closest_hit);
            const Hit far = embree.intersect(shadow);
            if (grazes(scene, shadow, near) || grazes(scene, shadow, far)) ++occlusion_graze;
            else ADD_FAILURE() << name << " " << kind << " shadow ray " << i << ": rtsim " << ours << ", Embree " << theirs;
        }
    }
    std::printf("[ embree    ] %s %s: %zu primitives, %d rays, %d hits; %d graze, %d tie and %d occlusion-graze "
                "disagreements\n",
                name.c_str(), kind, scene.triangles.size(), rays, hits, graze, tie, occlusion_graze);
    EXPECT_GT(hits, rays / 10) << name;
    EXPECT_EQ(other, 0) << name;
    EXPECT_LE(graze + occlusion_graze, rays / 1000) << name;
    // Consecutive capsules of a strand share their joint's sphere (same centre, same radius):
    // a ray meeting a strand there crosses both at one t.
    EXPECT_LE(tie, rays / 200) << name;
}

TEST(EmbreeSpheres, ParticlesFurballAndCapsules) {
    const std::string tmp = rtsim::test::process_temp_dir("embree_spheres").string();
    for (const char* name : {"particles", "furball", "furball_capsules"}) {
        const Scene scene = load_gltf(write_procedural_scene(name, tmp), true);
        for (const char* kind : {"bvh2", "cwbvh8"}) compare(name, scene, kind);
    }
}

}  // namespace
}  // namespace rtsim
