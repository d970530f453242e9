#pragma once
// Helpers for the grid and SBVH tests: random rays around a scene, hit comparison between any two
// tracers (structures, brute force), the plan tally that work counts must equal, and the
// procedural scenes read back through the glTF loader.
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../isect/isect_test_util.h"
#include "tests/cpp/process_temp_dir.h"
#include "traces/accel/accel.h"
#include "traces/bvh/build_tree.h"
#include "traces/isect/brute_force.h"
#include "traces/scene/gltf_loader.h"
#include "traces/scene/procedural.h"

namespace rtsim::test {

using Tracer = std::function<Hit(const Ray&, TraversalMode)>;

/// test::random_ray over `tris`, aimed a little more often and invalid a little less.
inline Ray accel_ray(Rng& rng, const std::vector<HwTriangle>& tris, const Aabb& bounds) {
    return random_ray(rng, bounds, tris.data(), tris.size(), RandomRayMix{0.4f, 0.005f});
}

/// The scene's triangles as hardware records, in primitive order.
inline std::vector<HwTriangle> hw_triangles(const Scene& scene) {
    std::vector<HwTriangle> out(scene.triangles.size());
    for (size_t i = 0; i < out.size(); ++i) out[i] = make_hw_triangle(scene, uint32_t(i));
    return out;
}

/// The default binary BVH of `scene`, loaded as the seam loads it.
inline std::unique_ptr<Accel> bvh2_of(const Scene& scene) { return load_accel(build_accel(scene, AccelOptions{}), "test bvh2"); }

inline Tracer brute_force(const std::vector<HwTriangle>& tris) {
    return [&tris](const Ray& r, TraversalMode m) { return trace_ray_brute_force(tris.data(), tris.size(), r, m); };
}

inline Tracer tracer(const Accel& accel, const StepOptions& step = {}) {
    return [&accel, step](const Ray& r, TraversalMode m) { return accel.trace(r, m, nullptr, step); };
}

struct Agreement {
    int rays = 0, hits = 0, diffs = 0;
};

/// Closest hits equal bit for bit (prim, inst, t, u, v) and any hits equal in hit/miss.
inline bool same_hit(const Hit& a, const Hit& b, TraversalMode mode) {
    if (mode == TraversalMode::any_hit) return a.valid() == b.valid();
    return a.prim == b.prim && a.inst == b.inst && float_bits(a.t) == float_bits(b.t) &&
           float_bits(a.u) == float_bits(b.u) && float_bits(a.v) == float_bits(b.v);
}

/// Compares `got` with `want` on the given rays in both modes; prints the first differences.
inline Agreement compare_rays(const Tracer& got, const Tracer& want, const std::vector<Ray>& rays,
                              const std::string& what) {
    Agreement ag;
    for (const Ray& r : rays) {
        ++ag.rays;
        for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
            const Hit a = got(r, mode), b = want(r, mode);
            ag.hits += mode == TraversalMode::closest_hit && b.valid();
            if (same_hit(a, b, mode)) continue;
            if (++ag.diffs <= 3)
                std::printf("%s: ray o=(%a %a %a) d=(%a %a %a) [%a %a] mode %d: got prim %d t %a, want prim %d t %a\n",
                            what.c_str(), r.origin.x, r.origin.y, r.origin.z, r.direction.x, r.direction.y,
                            r.direction.z, r.tmin, r.tmax, int(mode), a.prim, a.t, b.prim, b.t);
        }
    }
    return ag;
}

inline std::vector<Ray> random_rays(const Scene& scene, const std::vector<HwTriangle>& tris, uint64_t seed, int n) {
    Rng rng(seed);
    Aabb bounds;
    for (const HwTriangle& t : tris)
        for (const float* v : {t.v0, t.v1, t.v2}) bounds.grow(Vec3(v[0], v[1], v[2]));
    if (tris.empty()) bounds = Aabb{Vec3(-1.0f), Vec3(1.0f)};
    std::vector<Ray> rays(static_cast<size_t>(n));
    for (Ray& r : rays) r = accel_ray(rng, tris, bounds);
    (void)scene;
    return rays;
}

/// What a stepper's plans asked for, summed over a ray: the work counts must equal it.
inline WorkCounts tally_plans(Stepper& s, const Ray& ray, TraversalMode mode, int* max_fetches = nullptr) {
    WorkCounts w;
    s.begin(ray, mode);
    while (!s.done()) {
        const StepPlan& p = s.plan();
        if (max_fetches) *max_fetches = std::max(*max_fetches, int(p.fetch_count));
        for (int i = 0; i < p.fetch_count; ++i) {
            w.steps += p.fetch[i].kind == DataKind::node || p.fetch[i].kind == DataKind::cell;
            if (p.fetch[i].kind == DataKind::prim_ref) w.refs += p.fetch[i].bytes / 4;
        }
        for (int i = 0; i < p.op_count; ++i) {
            const Op& op = p.op[i];
            w[work_field_of(op.kind)] += op.count;  // the counter declared to count the kind's tests
        }
        const StepOutcome out = s.execute();
        for (int i = 0; i < out.op_count; ++i) w.anyhit_calls += out.op[i].count;
    }
    return w;
}

/// Procedural scene `name` read back through the glTF loader (hairball: 20000 triangles), once.
inline const Scene& procedural(const std::string& name) {
    static std::map<std::string, Scene> cache;
    auto it = cache.find(name);
    if (it != cache.end()) return it->second;
    const std::string dir = process_temp_dir("accel_scenes").string();
    ProceduralOptions options;
    options.hairball_triangles = 20000;
    return cache.emplace(name, load_gltf(write_procedural_scene(name, dir, options))).first->second;
}

}  // namespace rtsim::test
