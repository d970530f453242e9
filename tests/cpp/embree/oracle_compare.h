#pragma once
// Comparison of rtsim's trace_ray with the Embree oracle, ray by ray, with every disagreement
// classified by what explains it (docs/validation.md defines the classes). "The hit" is the one
// of the two tracers' hits that the other tracer did not report: for hit/miss, the only hit; for
// different prims at different t, the nearer one.
//   edge      the hit lies within 1e-4 (barycentric) of an edge or vertex of its triangle:
//             min(u, v, 1-u-v) < 1e-4 in the arithmetic of the tracer that reported it
//             (for ties at one t: either hit), or within 2^-20 L in world distance of an edge,
//             L the largest coordinate magnitude of the triangle and the origin (thin triangles);
//   tie       different prims at one t (t error <= 1e-4) that rtsim's arithmetic both hits:
//             overlapping or duplicated faces; rtsim takes the smaller id, Embree either;
//   alpha     the hit is on a MASK triangle whose alpha decision flips within 1e-4 in u or v:
//             the stochastic alpha pattern is a grid of 1/1024 cells in (u, v), and a cell
//             boundary is an edge of the opaque surface, judged like a triangle edge;
//   interval  the hit is within the t tolerance of tmin (origin on a surface, within rounding)
//             or of a finite tmax (shadow rays end just short of the light);
//   other     none of these: a real disagreement. The test requires zero.
// t error: |t_rtsim - t_embree| / max(t, farthest vertex of the hit triangle from the origin,
// in ray-direction units); the watertight t is good to a few ulps of that depth.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "embree_oracle.h"
#include "traces/bvh/hw_layout.h"
#include "traces/isect/ray_triangle.h"
#include "traces/accel/bvh2/bvh2.h"

namespace rtsim::oracle {

constexpr float kEdgeEps = 1e-4f;    ///< barycentric distance that counts as "on an edge"
constexpr float kTRelTol = 1e-4f;    ///< relative t tolerance where both hit
constexpr float kAlphaEps = 1e-4f;   ///< u, v perturbation that may flip an alpha decision

struct Tally {
    uint64_t rays = 0;
    uint64_t rtsim_hits = 0;
    uint64_t agree_miss = 0;     ///< both miss (closest) / both unoccluded (any hit)
    uint64_t agree_hit = 0;      ///< same prim, t within tolerance or not (closest) / both occluded (any hit)
    uint64_t t_out_of_tol = 0;   ///< same prim but t_error > kTRelTol
    double max_t_error = 0.0;    ///< over same-prim hits: |dt| / t scale (Comparer::t_scale)
    double max_rel_t = 0.0;      ///< over same-prim hits: |dt| / t, for information
    // One tracer hits, the other misses.
    uint64_t hm_edge = 0, hm_alpha = 0, hm_interval = 0, hm_other = 0;
    // Both hit different prims.
    uint64_t dp_edge = 0, dp_tie = 0, dp_alpha = 0, dp_interval = 0, dp_other = 0;

    uint64_t hit_miss() const { return hm_edge + hm_alpha + hm_interval + hm_other; }
    uint64_t diff_prim() const { return dp_edge + dp_tie + dp_alpha + dp_interval + dp_other; }
    uint64_t unexplained() const { return hm_other + dp_other; }
    double hit_miss_agreement() const { return rays ? 1.0 - double(hit_miss()) / double(rays) : 1.0; }
};

inline float rel_diff(float a, float b) {
    const float m = std::max(std::fabs(a), std::fabs(b));
    return m > 0.0f ? std::fabs(a - b) / m : 0.0f;
}

/// World-space edge distance that counts as "on an edge", relative to the largest coordinate
/// magnitude L of the triangle and the ray origin: 2^-20 L is 8 to 16 ulps of L. It matters for
/// thin triangles (hairball strands), where 1e-4 of a 0.003-wide strand is below float spacing.
constexpr float kEdgeUlps = 0x1p-20f;

class Comparer {
public:
    Comparer(const HwBvh& bvh, const EmbreeScene& embree) : m_bvh(bvh), m_embree(embree) {
        m_by_prim.resize(bvh.triangles.size());
        for (const HwTriangle& t : bvh.triangles) m_by_prim.at(t.prim) = &t;
    }

    void closest(const Ray& r, Tally* tally) const {
        const Hit a = trace_ray(m_bvh, r, TraversalMode::closest_hit);
        const Hit b = m_embree.intersect(r);
        tally->rays += 1;
        tally->rtsim_hits += a.valid();
        if (!a.valid() && !b.valid()) {
            tally->agree_miss += 1;
        } else if (a.valid() != b.valid()) {
            classify_hit_miss(r, a.valid() ? a : b, tally);
        } else if (a.prim == b.prim) {
            tally->agree_hit += 1;
            const float e = t_error(r, a, b);
            tally->max_t_error = std::max(tally->max_t_error, double(e));
            tally->max_rel_t = std::max(tally->max_rel_t, double(rel_diff(a.t, b.t)));
            tally->t_out_of_tol += e > kTRelTol;
            if (e > kTRelTol) report("t", r, a, b);
        } else if (t_error(r, a, b) <= kTRelTol) {
            // A tie at one distance: an edge both triangles share, or overlapping surfaces
            // (Sponza has double-sided faces stored twice, once per winding).
            if (near_edge(r, a) || near_edge(r, b)) tally->dp_edge += 1;
            else if (rtsim_hits_at(r, b)) tally->dp_tie += 1;
            else tally->dp_other += 1, report("tie", r, a, b);
        } else {
            // The nearer hit is the one the other tracer passed through: explain that one.
            const Hit& nearer = a.t < b.t ? a : b;
            if (near_edge(r, nearer)) tally->dp_edge += 1;
            else if (alpha_unstable(nearer)) tally->dp_alpha += 1;
            else if (at_interval_end(r, nearer)) tally->dp_interval += 1;
            else tally->dp_other += 1, report("prim", r, a, b);
        }
    }

    /// With RTSIM_ORACLE_VERBOSE set, prints a disagreement (rtsim hit a, Embree hit b).
    void report(const char* what, const Ray& r, const Hit& a, const Hit& b) const {
        static const bool verbose = std::getenv("RTSIM_ORACLE_VERBOSE") != nullptr;
        if (!verbose) return;
        std::printf("  %s: o (%a %a %a) d (%a %a %a) [%g %g]\n    rtsim  prim %d t %.9g u %.7g v %.7g %s\n"
                    "    embree prim %d t %.9g u %.7g v %.7g %s\n",
                    what, r.origin.x, r.origin.y, r.origin.z, r.direction.x, r.direction.y, r.direction.z,
                    r.tmin, r.tmax, a.prim, a.t, a.u, a.v, describe(r, a).c_str(), b.prim, b.t, b.u, b.v,
                    describe(r, b).c_str());
    }

    /// Cosine between the ray and the hit triangle's normal, and the triangle's edge lengths.
    std::string describe(const Ray& r, const Hit& h) const {
        if (!h.valid()) return "";
        const HwTriangle& t = *m_by_prim[size_t(h.prim)];
        const Vec3 p0(t.v0[0], t.v0[1], t.v0[2]), p1(t.v1[0], t.v1[1], t.v1[2]), p2(t.v2[0], t.v2[1], t.v2[2]);
        const Vec3 n = glm::cross(p1 - p0, p2 - p0);
        const float c = glm::dot(glm::normalize(n), glm::normalize(r.direction));
        char buf[160];
        std::snprintf(buf, sizeof buf, "cos %.3g edges %.3g %.3g %.3g cov %u", c, glm::length(p1 - p0),
                      glm::length(p2 - p1), glm::length(p0 - p2), m_embree.coverage_x255(uint32_t(h.prim)));
        return buf;
    }

    void any(const Ray& r, Tally* tally) const {
        const Hit a = trace_ray(m_bvh, r, TraversalMode::any_hit);
        const bool b = m_embree.occluded(r);
        tally->rays += 1;
        tally->rtsim_hits += a.valid();
        if (a.valid() == b) {
            (b ? tally->agree_hit : tally->agree_miss) += 1;
            return;
        }
        if (a.valid()) {
            classify_hit_miss(r, a, tally);
            return;
        }
        // Embree is occluded and rtsim is not: its closest hit in the interval stands for it.
        const Hit e = m_embree.intersect(r);
        if (!e.valid()) tally->hm_other += 1;
        else classify_hit_miss(r, e, tally);
    }

private:
    void classify_hit_miss(const Ray& r, const Hit& h, Tally* tally) const {
        if (near_edge(r, h)) tally->hm_edge += 1;
        else if (alpha_unstable(h)) tally->hm_alpha += 1;
        else if (at_interval_end(r, h)) tally->hm_interval += 1;
        else tally->hm_other += 1, report("hit/miss", r, h, Hit{});
    }

    /// The hit is within kEdgeEps (barycentric) or kEdgeUlps L (world distance) of an edge.
    bool near_edge(const Ray& r, const Hit& h) const {
        const float w[3] = {1.0f - h.u - h.v, h.u, h.v};  // weights of v0, v1, v2
        if (std::min({w[0], w[1], w[2]}) < kEdgeEps) return true;
        const HwTriangle& t = *m_by_prim[size_t(h.prim)];
        const Vec3 p[3] = {Vec3(t.v0[0], t.v0[1], t.v0[2]), Vec3(t.v1[0], t.v1[1], t.v1[2]),
                           Vec3(t.v2[0], t.v2[1], t.v2[2])};
        const float twice_area = glm::length(glm::cross(p[1] - p[0], p[2] - p[0]));
        float magnitude = std::max({std::fabs(r.origin.x), std::fabs(r.origin.y), std::fabs(r.origin.z)});
        for (const Vec3& q : p) magnitude = std::max({magnitude, std::fabs(q.x), std::fabs(q.y), std::fabs(q.z)});
        for (int i = 0; i < 3; ++i) {
            // Distance to the edge opposite vertex i: weight times the altitude from vertex i.
            const float altitude = twice_area / glm::length(p[(i + 2) % 3] - p[(i + 1) % 3]);
            if (w[i] * altitude < kEdgeUlps * magnitude) return true;
        }
        return false;
    }

    bool alpha_unstable(const Hit& h) const {
        const uint32_t cov = m_embree.coverage_x255(uint32_t(h.prim));
        if (cov == 0 || cov >= 255) return false;
        const bool base = alpha_test_accepts(uint32_t(h.prim), h.u, h.v, cov);
        for (float du : {-kAlphaEps, 0.0f, kAlphaEps})
            for (float dv : {-kAlphaEps, 0.0f, kAlphaEps})
                if (alpha_test_accepts(uint32_t(h.prim), h.u + du, h.v + dv, cov) != base) return true;
        return false;
    }

    /// Length scale of a hit's t: the larger of t and the farthest vertex of the hit triangle,
    /// in units of the ray direction. The watertight t is good to a few ulps of that depth
    /// (traversal.cpp), so a short t on a big triangle is compared at the triangle's scale.
    float t_scale(const Ray& r, const Hit& h) const {
        const HwTriangle& t = *m_by_prim[size_t(h.prim)];
        float depth = 0.0f;
        for (const float* v : {t.v0, t.v1, t.v2})
            depth = std::max(depth, glm::length(Vec3(v[0], v[1], v[2]) - r.origin));
        return std::max(std::fabs(h.t), depth / glm::length(r.direction));
    }

    /// |t_a - t_b| over the larger t scale of the two hits.
    float t_error(const Ray& r, const Hit& a, const Hit& b) const {
        return std::fabs(a.t - b.t) / std::max(t_scale(r, a), t_scale(r, b));
    }

    /// The hit is within the t tolerance of tmin (a ray starting on, within rounding, another
    /// surface) or of a finite tmax (shadow rays end just short of the light).
    bool at_interval_end(const Ray& r, const Hit& h) const {
        const float tol = kTRelTol * t_scale(r, h);
        return h.t - r.tmin <= tol || (std::isfinite(r.tmax) && r.tmax - h.t <= tol);
    }

    /// rtsim's arithmetic hits h.prim too, at h's distance (within tolerance): a tie.
    bool rtsim_hits_at(const Ray& r, const Hit& h) const {
        const HwTriangle& tri = *m_by_prim[size_t(h.prim)];
        TriangleHit th;
        const RayTrianglePre pre = ray_triangle_precompute(r);
        return intersect_triangle(pre, tri.v0, tri.v1, tri.v2, r.tmin, r.tmax, &th) &&
               std::fabs(th.t - h.t) <= kTRelTol * t_scale(r, h);
    }

    const HwBvh& m_bvh;
    const EmbreeScene& m_embree;
    std::vector<const HwTriangle*> m_by_prim;
};

/// One line per (scene, ray kind), quotable in docs/validation.md.
inline void print_tally(const std::string& scene, const char* kind, const Tally& t) {
    using ull = unsigned long long;
    std::printf("[ embree    ] %-8s %-8s rays %7llu  rtsim hits %7llu  agree %7llu (miss %llu, hit %llu)  "
                "hit/miss agreement %.4f%%\n"
                "[ embree    ] %-8s %-8s   diffs: hit/miss %llu [edge %llu alpha %llu interval %llu other %llu]  "
                "prim %llu [edge %llu tie %llu alpha %llu interval %llu other %llu]  "
                "t err max %.2e (rel %.2e, %llu > 1e-4)\n",
                scene.c_str(), kind, ull(t.rays), ull(t.rtsim_hits), ull(t.agree_miss + t.agree_hit),
                ull(t.agree_miss), ull(t.agree_hit), 100.0 * t.hit_miss_agreement(), scene.c_str(), kind,
                ull(t.hit_miss()), ull(t.hm_edge), ull(t.hm_alpha), ull(t.hm_interval), ull(t.hm_other),
                ull(t.diff_prim()), ull(t.dp_edge), ull(t.dp_tie), ull(t.dp_alpha), ull(t.dp_interval),
                ull(t.dp_other), t.max_t_error, t.max_rel_t, ull(t.t_out_of_tol));
    std::fflush(stdout);
}

}  // namespace rtsim::oracle
