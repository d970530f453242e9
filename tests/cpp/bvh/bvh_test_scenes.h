#pragma once
// Scenes for the BVH tests, built in code: one mesh of the given triangles, one identity
// instance, one material, flattened as a loader would.
#include <cmath>
#include <cstdint>
#include <vector>

#include "traces/common/rng.h"
#include "traces/scene/scene.h"

namespace rtsim::test {

inline Scene make_scene(const std::vector<Triangle>& triangles, const Material& material = {}) {
    Scene scene;
    Mesh mesh;
    mesh.name = "test_mesh";
    for (const Triangle& t : triangles) {
        mesh.positions.insert(mesh.positions.end(), {t.v0, t.v1, t.v2});
        mesh.materials.push_back(0);
    }
    scene.meshes.push_back(mesh);
    scene.instances.push_back(Instance{});
    scene.materials.push_back(material);
    scene.flatten();
    return scene;
}

/// Triangles of edge about `size` with centres uniform in [0, extent]^3.
inline std::vector<Triangle> random_triangles(size_t count, uint64_t seed, float extent = 1.0f,
                                              float size = 0.01f) {
    Rng rng(seed);
    std::vector<Triangle> out(count);
    for (Triangle& t : out) {
        Vec3 c(rng.next() * extent, rng.next() * extent, rng.next() * extent);
        auto jitter = [&] {
            return c + Vec3(rng.next() - 0.5f, rng.next() - 0.5f, rng.next() - 0.5f) * size;
        };
        t = Triangle{jitter(), jitter(), jitter()};
    }
    return out;
}

/// `clusters` tight balls of triangles scattered over a large cube: SAH finds the gaps,
/// an object median cuts through clusters.
inline std::vector<Triangle> clustered_triangles(size_t count, size_t clusters, uint64_t seed) {
    Rng rng(seed);
    std::vector<Vec3> centres(clusters);
    for (Vec3& c : centres) c = Vec3(rng.next(), rng.next(), rng.next()) * 100.0f;
    std::vector<Triangle> out;
    for (size_t i = 0; i < count; ++i) {
        // Uneven cluster sizes: cluster k gets about 2^-k of the triangles.
        size_t k = 0;
        while (k + 1 < clusters && rng.next() < 0.5f) ++k;
        Vec3 c = centres[k] + Vec3(rng.next(), rng.next(), rng.next()) * 2.0f;
        auto jitter = [&] { return c + Vec3(rng.next(), rng.next(), rng.next()) * 0.1f; };
        out.push_back(Triangle{jitter(), jitter(), jitter()});
    }
    return out;
}

}  // namespace rtsim::test
