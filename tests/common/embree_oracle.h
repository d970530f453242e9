#pragma once
// Embree 3 as an independent oracle for the reference tracer (tests and benchmark only; the
// tracer never links Embree). The scene is the flattened world-space triangle list, so Embree's
// (geometry, primitive) maps back to rtsim's stable primitive ids.
//
// Conventions bridged here:
//   * rtsim accepts tmin < t <= tmax, Embree tnear <= t <= tfar: tnear = nextafter(tmin, +inf).
//   * Embree's hit u, v are the weights of v1 and v2, as rtsim's Hit::u, Hit::v.
//   * Alpha MASK triangles go into a second geometry whose intersect and occluded filter
//     functions run rtsim's alpha_test_accepts(prim, u, v, coverage) on Embree's own u, v, so
//     Embree decides alpha exactly as the scene defines it, from its own arithmetic. Opaque
//     triangles have no filter (no cost on the benchmark's fast path).
#include <embree3/rtcore.h>

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "traces/common/ray.h"
#include "traces/accel/bvh2/bvh2.h"
#include "traces/scene/scene.h"

namespace rtsim::oracle {

/// rtsim's ray as Embree's, with rtsim's interval: tmin excluded (tnear just above it), tmax
/// included.
inline void embree_ray(const Ray& r, RTCRay* ray) {
    ray->org_x = r.origin.x;
    ray->org_y = r.origin.y;
    ray->org_z = r.origin.z;
    ray->dir_x = r.direction.x;
    ray->dir_y = r.direction.y;
    ray->dir_z = r.direction.z;
    ray->tnear = std::nextafter(r.tmin, std::numeric_limits<float>::infinity());
    ray->tfar = r.tmax;
    ray->time = 0.0f;
    ray->mask = 0xFFFFFFFFu;
    ray->id = 0;
    ray->flags = 0;
}

/// Alpha coverage x 255 of a material, as the BVH flattener stores it (255 for non-MASK).
inline uint32_t material_coverage_x255(const Material& m) {
    if (m.alpha_mode != AlphaMode::mask) return 255u;
    const float c = std::min(1.0f, std::max(0.0f, m.alpha_coverage));
    return uint32_t(std::lround(c * 255.0f));
}

class EmbreeScene {
public:
    struct Options {
        bool alpha = true;            ///< MASK triangles get the alpha filter (else opaque)
        bool robust = true;           ///< RTC_SCENE_FLAG_ROBUST
        RTCBuildQuality quality = RTC_BUILD_QUALITY_HIGH;
    };

    EmbreeScene(const Scene& scene, const Options& options) {
        m_device = rtcNewDevice("threads=1");
        if (!m_device) throw std::runtime_error("rtcNewDevice failed");
        m_scene = rtcNewScene(m_device);
        rtcSetSceneFlags(m_scene, options.robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
        rtcSetSceneBuildQuality(m_scene, options.quality);
        m_prims.reserve(2);  // FilterData points into it
        std::vector<uint32_t> opaque, masked;
        for (uint32_t p = 0; p < scene.triangle_count(); ++p) {
            const Material& m = scene.materials[scene.tri_material[p]];
            const uint32_t cov = material_coverage_x255(m);
            const bool is_masked = options.alpha && m.alpha_mode == AlphaMode::mask;
            (is_masked ? masked : opaque).push_back(p);
            m_coverage.push_back(cov);
        }
        add_geometry(scene, opaque, options, false);
        add_geometry(scene, masked, options, true);
        // The build proper: wall and this thread's CPU time (threads=1 builds on this thread).
        const auto w0 = std::chrono::steady_clock::now();
        const double c0 = thread_cpu_seconds();
        rtcCommitScene(m_scene);
        commit_cpu_seconds = thread_cpu_seconds() - c0;
        commit_wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
        check("rtcCommitScene");
    }
    ~EmbreeScene() {
        rtcReleaseScene(m_scene);
        rtcReleaseDevice(m_device);
    }
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;

    /// Closest hit in rtsim's terms (prim -1 and t = +inf on a miss).
    Hit intersect(const Ray& r) const {
        RTCRayHit rh;
        embree_ray(r, &rh.ray);
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        rtcIntersect1(m_scene, &ctx, &rh);
        Hit h;
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return h;
        h.prim = int32_t(m_prims[rh.hit.geomID][rh.hit.primID]);
        h.inst = 0;
        h.t = rh.ray.tfar;
        h.u = rh.hit.u;
        h.v = rh.hit.v;
        return h;
    }

    /// Any hit (occlusion) in the ray's interval.
    bool occluded(const Ray& r) const {
        RTCRay ray;
        embree_ray(r, &ray);
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        rtcOccluded1(m_scene, &ctx, &ray);
        return ray.tfar == -std::numeric_limits<float>::infinity();
    }

    uint32_t coverage_x255(uint32_t prim) const { return m_coverage[prim]; }

    double commit_wall_seconds = 0.0;  ///< rtcCommitScene (the BVH build), wall time
    double commit_cpu_seconds = 0.0;   ///< the same, this thread's CPU time

    static double thread_cpu_seconds() {
        timespec ts{};
        clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
        return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
    }

private:
    /// One triangle geometry over the given primitive ids (float3 vertices, no index sharing).
    void add_geometry(const Scene& scene, const std::vector<uint32_t>& prims, const Options& o, bool masked) {
        if (prims.empty()) return;
        RTCGeometry g = rtcNewGeometry(m_device, RTC_GEOMETRY_TYPE_TRIANGLE);
        rtcSetGeometryBuildQuality(g, o.quality);
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                              3 * sizeof(float), 3 * prims.size()));
        auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                   3 * sizeof(uint32_t), prims.size()));
        for (size_t i = 0; i < prims.size(); ++i) {
            const Triangle& t = scene.triangles[prims[i]];
            const Vec3* vs[3] = {&t.v0, &t.v1, &t.v2};
            for (int k = 0; k < 3; ++k) {
                v[9 * i + 3 * k + 0] = vs[k]->x;
                v[9 * i + 3 * k + 1] = vs[k]->y;
                v[9 * i + 3 * k + 2] = vs[k]->z;
                idx[3 * i + k] = uint32_t(3 * i + k);
            }
        }
        if (masked) {
            m_filter.prims = &m_prims_storage_for(prims);
            m_filter.coverage = &m_coverage;
            rtcSetGeometryUserData(g, &m_filter);
            rtcSetGeometryIntersectFilterFunction(g, &alpha_filter);
            rtcSetGeometryOccludedFilterFunction(g, &alpha_filter);
        } else {
            m_prims_storage_for(prims);
        }
        rtcCommitGeometry(g);
        if (rtcAttachGeometry(m_scene, g) != m_prims.size() - 1) throw std::runtime_error("geometry id");
        rtcReleaseGeometry(g);
        check("geometry");
    }

    std::vector<uint32_t>& m_prims_storage_for(const std::vector<uint32_t>& prims) {
        m_prims.push_back(prims);
        return m_prims.back();
    }

    struct FilterData {
        const std::vector<uint32_t>* prims = nullptr;
        const std::vector<uint32_t>* coverage = nullptr;
    };

    /// The alpha test on Embree's candidate hit: rejecting it (valid = 0) makes Embree go on.
    static void alpha_filter(const RTCFilterFunctionNArguments* args) {
        const auto* data = static_cast<const FilterData*>(args->geometryUserPtr);
        for (unsigned i = 0; i < args->N; ++i) {
            if (args->valid[i] == 0) continue;
            const uint32_t prim = (*data->prims)[RTCHitN_primID(args->hit, args->N, i)];
            const float u = RTCHitN_u(args->hit, args->N, i), v = RTCHitN_v(args->hit, args->N, i);
            if (!alpha_test_accepts(prim, u, v, (*data->coverage)[prim])) args->valid[i] = 0;
        }
    }


    void check(const char* what) const {
        const RTCError e = rtcGetDeviceError(m_device);
        if (e != RTC_ERROR_NONE) throw std::runtime_error(std::string("Embree error in ") + what);
    }

    RTCDevice m_device = nullptr;
    RTCScene m_scene = nullptr;
    std::vector<std::vector<uint32_t>> m_prims;  ///< per geometry id: Embree primID -> rtsim prim
    std::vector<uint32_t> m_coverage;            ///< per prim: alpha coverage x 255
    FilterData m_filter;
};

}  // namespace rtsim::oracle
