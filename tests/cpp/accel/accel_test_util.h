#pragma once
// Helpers for the structure tests: every registered kind built through the registry (as the
// tracer builds it), random rays around a scene, and bit-exact hit comparison.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/cpp/error_of.h"
#include "../isect/isect_test_util.h"
#include "traces/accel/accel.h"
#include "traces/accel/cwbvh/cwbvh.h"
#include "traces/accel/wide/wide_accel.h"
#include "traces/common/error.h"
#include "traces/scene/scene.h"

namespace rtsim::test {

/// The wide and compressed BVHs.
inline const std::vector<std::string>& wide_kinds() {
    static const std::vector<std::string> kinds = {"bvh4", "bvh6", "bvh8", "cwbvh6", "cwbvh8", "bvh8_octant",
                                                   "cwbvh8_octant"};
    return kinds;
}

/// Suffix of a kind name that builds it with compressed leaves ("cwbvh8+cl"; leaf_blocks.h).
inline const std::string kCompressedLeaves = "+cl";

/// The kinds, each also with compressed leaves.
inline std::vector<std::string> with_compressed_leaves(const std::vector<std::string>& kinds) {
    std::vector<std::string> out = kinds;
    for (const std::string& k : kinds) out.push_back(k + kCompressedLeaves);
    return out;
}

inline std::unique_ptr<Accel> build_kind(const Scene& scene, const std::string& kind, uint32_t max_leaf_size = 4) {
    AccelOptions o;
    o.kind = kind;
    const size_t cl = kind.size() >= kCompressedLeaves.size() ? kind.size() - kCompressedLeaves.size() : 0;
    if (kind.compare(cl, std::string::npos, kCompressedLeaves) == 0) {
        o.kind = kind.substr(0, cl);
        o.settings["compressed_leaves"] = true;
    }
    o.build.max_leaf_size = max_leaf_size;
    return load_accel(build_accel(scene, o), kind);
}

/// Bit-identical hits (prim, instance, t, u, v).
inline bool same_hit(const Hit& a, const Hit& b) {
    return a.prim == b.prim && a.inst == b.inst && float_bits(a.t) == float_bits(b.t) &&
           float_bits(a.u) == float_bits(b.u) && float_bits(a.v) == float_bits(b.v);
}

/// The SSE2 fused loop of an fp32 kind or of cwbvh8 in distance order (Accel::trace runs the best
/// the CPU has: AVX for 8-wide nodes, AVX2 for compressed ones, where present), or nothing for
/// other kinds.
inline Hit trace_sse2(const Accel& accel, const Ray& r, TraversalMode mode, WorkCounts* work, bool* ran) {
    *ran = true;
    if (auto* a = dynamic_cast<const WideAccel<Fp32Codec<4>>*>(&accel))
        return trace_wide_fused<4>(a->view(), r, mode, work, WideSimd::sse2);
    if (auto* a = dynamic_cast<const WideAccel<Fp32Codec<6>>*>(&accel))
        return trace_wide_fused<6>(a->view(), r, mode, work, WideSimd::sse2);
    auto* a = dynamic_cast<const WideAccel<Fp32Codec<8>>*>(&accel);
    if (a && a->view().order == ChildOrder::distance) return trace_wide_fused<8>(a->view(), r, mode, work, WideSimd::sse2);
    auto* c = dynamic_cast<const WideAccel<Cw8Codec>*>(&accel);
    if (c && c->view().order == ChildOrder::distance) return trace_cwbvh8_fused(c->view(), r, mode, work, WideSimd::sse2);
    *ran = false;
    return Hit{};
}

inline const Region& triangles_of(const Accel& a) { return a.image().region("triangles"); }

/// A mesh of `triangles` small random triangles in [-1.3, 1.3]^3 (the two-level tests' BLASes).
inline Mesh soup_mesh(uint64_t seed, int triangles) {
    Rng rng(seed);
    Mesh m;
    m.name = "soup";
    for (int i = 0; i < triangles; ++i) {
        const Vec3 c = random_point(rng, Vec3(-1.0f), Vec3(1.0f));
        for (int k = 0; k < 3; ++k) m.positions.push_back(c + 0.3f * random_point(rng, Vec3(-1.0f), Vec3(1.0f)));
    }
    m.materials.assign(m.positions.size() / 3, 0);
    return m;
}

}  // namespace rtsim::test
