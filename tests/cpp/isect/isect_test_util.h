#pragma once
// Scenes and rays for the intersection tests, built in code (no files).
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <utility>
#include <vector>

#include "traces/bvh/builder.h"
#include "traces/bvh/hw_layout.h"
#include "traces/common/ray.h"
#include "traces/common/rng.h"
#include "traces/scene/scene.h"

namespace rtsim::test {

constexpr float kInf = std::numeric_limits<float>::infinity();

/// A scene with one mesh (triangle soup), one identity instance and the given materials;
/// material_of[i] picks triangle i's material (all 0 when empty).
inline Scene make_scene(const std::vector<Vec3>& soup, std::vector<Material> materials = {Material{}},
                        const std::vector<uint32_t>& material_of = {}) {
    Scene scene;
    Mesh mesh;
    mesh.name = "test";
    mesh.positions = soup;
    mesh.materials.assign(soup.size() / 3, 0u);
    if (!material_of.empty()) mesh.materials = material_of;
    scene.meshes.push_back(mesh);
    scene.instances.push_back(Instance{});
    scene.materials = std::move(materials);
    scene.flatten();
    return scene;
}

inline HwBvh build(const Scene& scene, uint32_t max_leaf_size = 4) {
    BuildConfig config;
    config.max_leaf_size = max_leaf_size;
    return build_bvh(scene, config);
}

/// Cube [-1, 1]^3, each face an n x n grid of quads (2 triangles each). Grid coordinates come
/// from one expression, so shared vertices are bitwise identical.
inline std::vector<Vec3> tessellated_cube(int n) {
    std::vector<Vec3> soup;
    auto coord = [n](int i) { return -1.0f + 2.0f * float(i) / float(n); };
    for (int axis = 0; axis < 3; ++axis) {
        for (float side : {-1.0f, 1.0f}) {
            const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
            auto p = [&](int i, int j) {
                Vec3 v;
                v[axis] = side;
                v[a1] = coord(i);
                v[a2] = coord(j);
                return v;
            };
            for (int i = 0; i < n; ++i)
                for (int j = 0; j < n; ++j) {
                    soup.insert(soup.end(), {p(i, j), p(i + 1, j), p(i + 1, j + 1)});
                    soup.insert(soup.end(), {p(i, j), p(i + 1, j + 1), p(i, j + 1)});
                }
        }
    }
    return soup;
}

/// Icosphere of radius 1 (subdivided icosahedron); shared vertices are bitwise identical.
inline std::vector<Vec3> icosphere(int subdivisions) {
    const float g = 1.6180339887f;
    std::vector<Vec3> v = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                           {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
    for (Vec3& p : v) p = glm::normalize(p);
    std::vector<uint32_t> idx = {0, 11, 5, 0, 5,  1, 0, 1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
                                 4, 11, 10, 2, 10, 7, 6, 7, 1, 8, 3, 9, 4, 3, 4, 2, 3, 2, 6, 3,
                                 6, 8, 3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1};
    for (int s = 0; s < subdivisions; ++s) {
        std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
        auto midpoint = [&](uint32_t a, uint32_t b) {
            auto key = std::minmax(a, b);
            auto it = mid.find(key);
            if (it != mid.end()) return it->second;
            v.push_back(glm::normalize(v[key.first] + v[key.second]));
            return mid[key] = uint32_t(v.size() - 1);
        };
        std::vector<uint32_t> next;
        for (size_t t = 0; t < idx.size(); t += 3) {
            uint32_t a = idx[t], b = idx[t + 1], c = idx[t + 2];
            uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
            next.insert(next.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
        }
        idx = next;
    }
    std::vector<Vec3> soup;
    for (uint32_t i : idx) soup.push_back(v[i]);
    return soup;
}

/// Uniform direction on the unit sphere.
inline Vec3 random_direction(Rng& rng) {
    const float z = 2.0f * rng.next() - 1.0f;
    const float phi = 6.28318530718f * rng.next();
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    return Vec3(r * std::cos(phi), r * std::sin(phi), z);
}

inline Vec3 random_point(Rng& rng, const Vec3& lo, const Vec3& hi) {
    return lo + (hi - lo) * Vec3(rng.next(), rng.next(), rng.next());
}

inline Ray make_ray(const Vec3& o, const Vec3& d, float tmin = 0.0f,
                    float tmax = std::numeric_limits<float>::infinity()) {
    Ray r;
    r.origin = o;
    r.direction = d;
    r.tmin = tmin;
    r.tmax = tmax;
    return r;
}

/// How often random_ray aims at a triangle and makes an invalid (NaN tmin) ray.
struct RandomRayMix {
    float aimed = 0.3f;
    float invalid = 0.01f;
};

/// Random rays around `bounds`: random and +-0 directions, clipped intervals, some aimed at a
/// vertex or the interior of one of the `tri_count` triangles `tris`, a few invalid.
inline Ray random_ray(Rng& rng, const Aabb& bounds, const HwTriangle* tris, uint64_t tri_count,
                      RandomRayMix mix = {}) {
    const Vec3 extent = bounds.hi - bounds.lo;
    const Vec3 o = random_point(rng, bounds.lo - 0.2f * extent, bounds.hi + 0.2f * extent);
    Vec3 d = random_direction(rng);
    if (rng.next() < mix.aimed && tri_count) {
        const HwTriangle& t = tris[uint64_t(rng.next() * float(tri_count)) % tri_count];
        const Vec3 v0(t.v0[0], t.v0[1], t.v0[2]), v1(t.v1[0], t.v1[1], t.v1[2]), v2(t.v2[0], t.v2[1], t.v2[2]);
        const float a = rng.next(), b = rng.next() * (1.0f - a);
        const Vec3 target = rng.next() < 0.3f ? v0 : v0 + a * (v1 - v0) + b * (v2 - v0);
        if (target != o) d = target - o;
    }
    for (int a = 0; a < 3; ++a)
        if (rng.next() < 0.05f) d[a] = rng.next() < 0.5f ? 0.0f : -0.0f;
    if (d == Vec3(0.0f)) d.z = 1.0f;
    const float len = glm::length(extent);
    float tmin = 0.0f, tmax = std::numeric_limits<float>::infinity();
    if (rng.next() < 0.3f) {
        tmin = rng.next() * len * 0.5f;
        tmax = tmin + rng.next() * len;
    }
    if (rng.next() < mix.invalid) tmin = std::numeric_limits<float>::quiet_NaN();
    return make_ray(o, d, tmin, tmax);
}

/// Rays on the lattice of a tessellated cube (tessellated_cube, scaled and offset): along faces
/// and edges (+-0 components), through vertices and corners (crossings on two or three axes at
/// one t), from inside, outside and on the bounds. Directions scale with the scene so distances
/// stay near 1 whatever the scale.
inline std::vector<Ray> lattice_rays(float scale, const Vec3& offset) {
    std::vector<Ray> rays;
    const float coords[] = {-1.5f, -1.0f, -0.75f, 0.0f, 0.25f, 1.0f, 1.25f};
    const Vec3 dirs[] = {Vec3(1, 0, 0),  Vec3(-0.0f, 1, 0), Vec3(0, -0.0f, -1),    Vec3(1, 1, 0),
                         Vec3(-1, 1, 1), Vec3(1, -1, -1), Vec3(0.5f, 0.25f, -1), Vec3(-0.0f, 0.0f, 1)};
    for (float x : coords)
        for (float y : coords)
            for (float z : coords)
                for (const Vec3& d : dirs) {
                    rays.push_back(make_ray(offset + scale * Vec3(x, y, z), scale * d));
                    rays.push_back(make_ray(offset + scale * Vec3(x, y, z), -scale * d));
                }
    return rays;
}

inline uint32_t float_bits(float f) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
}

/// Random soup: triangles of mixed sizes, some axis-aligned, some duplicated (ties), half of
/// them on an alpha-MASK material with coverage 0.5.
inline Scene random_soup(uint64_t seed, int count) {
    Rng rng(seed);
    std::vector<Vec3> soup;
    std::vector<uint32_t> material_of;
    for (int i = 0; i < count; ++i) {
        const float size = std::ldexp(1.0f, -int(rng.next() * 6.0f));
        const Vec3 c = random_point(rng, Vec3(-4), Vec3(4));
        Vec3 p[3];
        for (Vec3& q : p) q = c + size * random_point(rng, Vec3(-1), Vec3(1));
        const float kind = rng.next();
        if (kind < 0.15f) {
            const int axis = int(rng.next() * 3.0f) % 3;  // axis-aligned: a flat leaf box
            for (Vec3& q : p) q[axis] = c[axis];
        }
        soup.insert(soup.end(), {p[0], p[1], p[2]});
        material_of.push_back(rng.next() < 0.5f ? 1u : 0u);
        if (kind > 0.9f) {  // a coincident copy: same vertices, another prim id
            soup.insert(soup.end(), {p[0], p[1], p[2]});
            material_of.push_back(0u);
        }
    }
    Material masked;
    masked.alpha_mode = AlphaMode::mask;
    masked.alpha_coverage = 0.5f;
    return make_scene(soup, {Material{}, masked}, material_of);
}

}  // namespace rtsim::test
