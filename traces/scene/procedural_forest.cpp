// Forest and grove: thousands of instances of a few detailed meshes, the scene that
// needs a two-level structure. "forest" places 72 x 72 trees and rocks (about 4.6 x 10^8
// triangles if flattened: more than this machine can flatten); "grove" places 6 x 6 of the same
// meshes (about 3.4 x 10^6 flattened), small enough to compare flattened against two-level.
// Each instance: a jittered grid position, a random turn about +Y, a non-uniform scale and, for
// one in eight, a mirror (negative determinant).
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "traces/common/rng.h"
#include "traces/scene/procedural_shapes.h"

namespace rtsim {

namespace {

constexpr double kSpacing = 6.0;  ///< metres between grid positions

/// A pine: trunk and a layered canopy of 40 tiers, lathed with 600 segments (~97,000 triangles).
void add_pine(TriangleSoup& bark, TriangleSoup& leaves) {
    add_lathe(bark, {{0.0f, 0.0f}, {0.25f, 0.0f}, {0.18f, 3.0f}, {0.0f, 3.0f}}, 600);
    std::vector<glm::vec2> canopy{{0.0f, 1.5f}};
    for (int tier = 0; tier < 40; ++tier) {
        const float y = 1.5f + 0.16f * float(tier), r = 2.0f * (1.0f - float(tier) / 40.0f);
        canopy.push_back({r, y});
        canopy.push_back({0.55f * r, y + 0.16f});
    }
    canopy.push_back({0.0f, 8.2f});
    add_lathe(leaves, canopy, 600);
}

/// A broadleaf: trunk and a sphere canopy of 160 x 300 (~97,000 triangles).
void add_broadleaf(TriangleSoup& bark, TriangleSoup& leaves) {
    add_lathe(bark, {{0.0f, 0.0f}, {0.3f, 0.0f}, {0.22f, 2.5f}, {0.0f, 2.5f}}, 96);
    add_sphere(leaves, Vec3(0.0f, 4.0f, 0.0f), 2.2f, 160, 300);
}

/// A rock: a squashed torus of 240 x 120 (~58,000 triangles).
void add_rock(TriangleSoup& rock) {
    glm::dmat4 m = glm::scale(glm::dmat4(1.0), glm::dvec3(1.0, 0.5, 1.0));
    m = glm::rotate(m, glm::radians(90.0), glm::dvec3(1, 0, 0));
    add_torus(rock, 0.8f, 0.45f, 240, 120, m);
}

std::string write_forest_of(const std::string& dir, const std::string& name, int side, uint64_t seed) {
    TriangleSoup pine_bark, pine_leaves, oak_bark, oak_leaves, rock, ground;
    add_pine(pine_bark, pine_leaves);
    add_broadleaf(oak_bark, oak_leaves);
    add_rock(rock);
    const float half = float(kSpacing * side / 2.0 + kSpacing);
    ground.add_quad({-half, 0, -half}, {half, 0, -half}, {half, 0, half}, {-half, 0, half}, {0, 1, 0});

    GltfWriter w;
    const int m_bark = w.add_material(make_material("bark", {0.35f, 0.25f, 0.15f}, 0.0f, 0.9f));
    const int m_leaf = w.add_material(make_material("leaves", {0.15f, 0.45f, 0.12f}, 0.0f, 0.7f));
    const int m_rock = w.add_material(make_material("rock", {0.5f, 0.5f, 0.48f}, 0.0f, 0.6f));
    const int m_ground = w.add_material(make_material("ground", {0.3f, 0.25f, 0.2f}, 0.0f, 1.0f));
    const int meshes[3] = {w.add_mesh("pine", {{&pine_bark, m_bark}, {&pine_leaves, m_leaf}}),
                           w.add_mesh("broadleaf", {{&oak_bark, m_bark}, {&oak_leaves, m_leaf}}),
                           w.add_mesh("rock", {{&rock, m_rock}})};
    w.add_mesh_node("ground", w.add_mesh("ground", {{&ground, m_ground}}));
    for (int i = 0; i < side; ++i)
        for (int j = 0; j < side; ++j) {
            Rng rng(hash_combine(seed, 0x666f72657374ull /*"forest"*/, uint64_t(i * side + j)));
            const double x = kSpacing * (i - (side - 1) / 2.0) + 2.0 * (rng.next() - 0.5);
            const double z = kSpacing * (j - (side - 1) / 2.0) + 2.0 * (rng.next() - 0.5);
            const float pick = rng.next();
            const int mesh = pick < 0.45f ? 0 : pick < 0.9f ? 1 : 2;
            const double s = 0.7 + 0.6 * rng.next(), sy = s * (0.8 + 0.6 * rng.next());
            const double mirror = rng.next() < 0.125f ? -1.0 : 1.0;
            glm::dmat4 m = glm::translate(glm::dmat4(1.0), glm::dvec3(x, 0.0, z));
            m = glm::rotate(m, 2.0 * M_PI * rng.next(), glm::dvec3(0, 1, 0));
            m = glm::scale(m, glm::dvec3(mirror * s, sy, s));
            w.add_mesh_node("tree_" + std::to_string(i) + "_" + std::to_string(j), meshes[mesh], m);
        }
    w.add_light("sun", LightType::directional, {0.0f, 100.0f, 0.0f}, {30.0f, 0.0f, 20.0f}, {1, 0.95f, 0.9f}, 3.0f);
    const float back = float(kSpacing * side / 2.0);
    w.add_camera("camera", {-back, 12.0f, -back}, {0.0f, 0.0f, 0.0f}, 0.8f, 4.0f / 3.0f);
    return w.write(dir, name);
}

}  // namespace

std::string write_forest(const std::string& dir, const ProceduralOptions& options) {
    return write_forest_of(dir, "forest", 72, options.seed);
}

std::string write_grove(const std::string& dir, const ProceduralOptions& options) {
    return write_forest_of(dir, "grove", 6, options.seed);
}

}  // namespace rtsim
