// Two-level structures against Embree 3's own instancing: one Embree scene per mesh geometry in
// object space, a top scene of instance geometries with the instances' transforms (rounded to
// float as rtsim stores them), the same rays. Hits must name the same instance and primitive;
// every disagreement must be a hit within 1e-4 (barycentric) of an edge in one tracer's
// arithmetic, or a tie (two primitives at one t, e.g. a trunk's base on the ground: rtsim takes
// the smaller id, Embree either) (docs/validation.md's classes).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <embree3/rtcore.h>
#include <gtest/gtest.h>

#include "traces/accel/accel.h"
#include "traces/accel/two_level/instance_record.h"
#include "traces/accel/two_level/two_level.h"
#include "traces/common/rng.h"
#include "traces/scene/gltf_loader.h"
#include "traces/scene/procedural.h"
#include "tests/cpp/process_temp_dir.h"

namespace rtsim {
namespace {

/// Embree's instancing of a scene kept as instances (opaque triangles only).
class EmbreeInstanced {
public:
    explicit EmbreeInstanced(const Scene& scene) : m_scene(scene) {
        m_device = rtcNewDevice("threads=1");
        m_top = rtcNewScene(m_device);
        rtcSetSceneFlags(m_top, RTC_SCENE_FLAG_ROBUST);
        const std::vector<uint32_t> cls = geometry_classes(scene);
        std::vector<RTCScene> blas(scene.meshes.size(), nullptr);
        for (uint32_t i = 0; i < scene.instances.size(); ++i) {
            const Instance& inst = scene.instances[i];
            if (scene.meshes[inst.mesh].triangle_count() == 0) continue;
            RTCScene& b = blas[cls[inst.mesh]];
            if (!b) b = mesh_scene(scene.meshes[cls[inst.mesh]]);
            RTCGeometry g = rtcNewGeometry(m_device, RTC_GEOMETRY_TYPE_INSTANCE);
            rtcSetGeometryInstancedScene(g, b);
            float rows[12];
            store_affine_rows(inst.object_to_world, rows);
            rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, rows);
            rtcCommitGeometry(g);
            rtcAttachGeometryByID(m_top, g, i);
            rtcReleaseGeometry(g);
        }
        rtcCommitScene(m_top);
        for (RTCScene b : blas)
            if (b) rtcReleaseScene(b);
    }
    ~EmbreeInstanced() {
        rtcReleaseScene(m_top);
        rtcReleaseDevice(m_device);
    }

    Hit intersect(const Ray& r) const {
        RTCRayHit rh{};
        rh.ray.org_x = r.origin.x, rh.ray.org_y = r.origin.y, rh.ray.org_z = r.origin.z;
        rh.ray.dir_x = r.direction.x, rh.ray.dir_y = r.direction.y, rh.ray.dir_z = r.direction.z;
        rh.ray.tnear = r.tmin, rh.ray.tfar = r.tmax, rh.ray.mask = 0xFFFFFFFFu;
        rh.hit.geomID = rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        rtcIntersect1(m_top, &ctx, &rh);
        Hit h;
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return h;
        h.inst = int32_t(rh.hit.instID[0]);
        h.prim = int32_t(m_scene.instances[rh.hit.instID[0]].prim_base + rh.hit.primID);
        h.t = rh.ray.tfar, h.u = rh.hit.u, h.v = rh.hit.v;
        return h;
    }

private:
    RTCScene mesh_scene(const Mesh& mesh) {
        RTCScene s = rtcNewScene(m_device);
        rtcSetSceneFlags(s, RTC_SCENE_FLAG_ROBUST);
        RTCGeometry g = rtcNewGeometry(m_device, RTC_GEOMETRY_TYPE_TRIANGLE);
        const size_t n = mesh.triangle_count();
        auto* v = static_cast<float*>(
            rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * n));
        auto* idx = static_cast<uint32_t*>(
            rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), n));
        for (size_t k = 0; k < 3 * n; ++k) {
            v[3 * k] = mesh.positions[k].x, v[3 * k + 1] = mesh.positions[k].y, v[3 * k + 2] = mesh.positions[k].z;
            idx[k] = uint32_t(k);
        }
        rtcCommitGeometry(g);
        rtcAttachGeometry(s, g);
        rtcReleaseGeometry(g);
        rtcCommitScene(s);
        return s;
    }

    const Scene& m_scene;
    RTCDevice m_device;
    RTCScene m_top;
};

bool near_edge(const Hit& h) { return h.valid() && std::min({h.u, h.v, 1.0f - h.u - h.v}) < 1e-4f; }

/// Rays from around the scene's box towards random points inside it.
void compare_with_embree(const std::string& name, const Scene& scene) {
    AccelOptions o;
    o.two_level = true;
    const std::unique_ptr<Accel> two = load_accel(build_accel(scene, o), name);
    const EmbreeInstanced embree(scene);
    Rng rng(5);
    const Vec3 lo = scene.bounds.lo, ext = scene.bounds.hi - scene.bounds.lo;
    auto point = [&](float margin) {
        return lo - margin * ext + (1.0f + 2.0f * margin) * Vec3(rng.next(), rng.next(), rng.next()) * ext;
    };
    int rays = 4000, hits = 0, edge = 0, tie = 0, other = 0;
    for (int i = 0; i < rays; ++i) {
        Ray r;
        r.origin = point(0.3f);
        r.direction = point(0.0f) - r.origin;
        const Hit a = two->trace(r, TraversalMode::closest_hit), b = embree.intersect(r);
        hits += a.valid();
        if (a.valid() == b.valid() && (!a.valid() || (a.prim == b.prim && a.inst == b.inst))) continue;
        if (near_edge(a) || near_edge(b)) {
            ++edge;
            continue;
        }
        if (a.valid() && b.valid() && std::fabs(a.t - b.t) <= 1e-6f * a.t && a.prim < b.prim) {
            ++tie;
            continue;
        }
        ++other;
        ADD_FAILURE() << name << " ray " << i << ": rtsim prim " << a.prim << " inst " << a.inst << " t " << a.t
                      << "; Embree prim " << b.prim << " inst " << b.inst << " t " << b.t;
    }
    std::printf("[ embree    ] %s instancing: %d rays, %d hits, %d edge and %d tie disagreements\n", name.c_str(),
                rays, hits, edge, tie);
    EXPECT_GT(hits, rays / 10) << name;
    EXPECT_EQ(other, 0) << name;
    EXPECT_LE(edge + tie, rays / 200) << name;
}

TEST(EmbreeInstancing, SharedScenesAndGrove) {
    const char* env = std::getenv("RTSIM_SCENES");
    const std::string dir = env && *env ? env : RTSIM_SCENES_DIR;
    for (const char* name : {"SimpleInstancing", "MetalRoughSpheresNoTextures"}) {
        const std::string path = dir + "/" + name + "/" + name + ".gltf";
        if (std::filesystem::exists(path)) compare_with_embree(name, load_gltf(path, false));
    }
    const std::string tmp = rtsim::test::process_temp_dir("embree_instancing").string();
    compare_with_embree("grove", load_gltf(write_procedural_scene("grove", tmp), false));
}

}  // namespace
}  // namespace rtsim
