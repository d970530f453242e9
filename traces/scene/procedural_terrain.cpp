// Terrain: a height field of rolling hills under a low sun, covered evenly in grass blades. The
// uniform scene seed 001 names as the grid's good case: primitives of about one size spread at
// about one density over the whole scene, so a uniform grid's cells hold similar counts and few
// are empty, where a BVH's boxes over a flat-ish sheet overlap. The grass is geometry (three
// thin triangles a blade). The meadow is the same hills with the grass as games draw it:
// alpha-tested cards, upright quads whose MASK material passes a fraction of their hits (the
// stochastic alpha test of extras.textureAlphaCoverage; the writer has no textures), so every
// ray through the grass runs any-hit tests.
#include <cmath>

#include "traces/common/rng.h"
#include "traces/scene/procedural_shapes.h"

namespace rtsim {

namespace {

constexpr int kTerrainCells = 128;           ///< height-field quads a side (2 x 128^2 triangles)
constexpr float kTerrainHalf = 40.0f;        ///< metres from the centre to an edge
constexpr uint32_t kTerrainBlades = 12000;   ///< grass blades, 3 triangles each
constexpr float kTerrainHills = 3.0f;        ///< height amplitude, metres
constexpr uint32_t kMeadowCards = 8000;      ///< grass cards, 2 triangles each
constexpr float kMeadowCoverage = 0.35f;     ///< fraction of a card's texels that are blades

/// Value noise on an integer lattice, smoothly interpolated (a classic fBm building block).
float lattice(int x, int z, uint64_t seed) {
    return float(hash_combine(seed, uint64_t(uint32_t(x)), uint64_t(uint32_t(z))) >> 40) / float(1 << 24);
}

float value_noise(float x, float z, uint64_t seed) {
    const int x0 = int(std::floor(x)), z0 = int(std::floor(z));
    const float fx = x - float(x0), fz = z - float(z0);
    const float sx = fx * fx * (3 - 2 * fx), sz = fz * fz * (3 - 2 * fz);
    const float a = lattice(x0, z0, seed), b = lattice(x0 + 1, z0, seed);
    const float c = lattice(x0, z0 + 1, seed), d = lattice(x0 + 1, z0 + 1, seed);
    return (a + (b - a) * sx) * (1 - sz) + (c + (d - c) * sx) * sz;
}

/// Four octaves of value noise: hills of about 20 m with bumps down to about 2.5 m.
float height(float x, float z, uint64_t seed) {
    float h = 0, amplitude = kTerrainHills, frequency = 1.0f / 20.0f;
    for (int octave = 0; octave < 4; ++octave) {
        h += amplitude * (value_noise(x * frequency, z * frequency, seed + uint64_t(octave)) - 0.5f);
        amplitude *= 0.5f, frequency *= 2.0f;
    }
    return h;
}

TriangleSoup height_field(uint64_t seed) {
    TriangleSoup ground;
    const float step = 2 * kTerrainHalf / kTerrainCells;
    for (int j = 0; j <= kTerrainCells; ++j)
        for (int i = 0; i <= kTerrainCells; ++i) {
            const float x = -kTerrainHalf + float(i) * step, z = -kTerrainHalf + float(j) * step;
            ground.add_vertex(Vec3(x, height(x, z, seed), z));
        }
    for (int j = 0; j < kTerrainCells; ++j)
        for (int i = 0; i < kTerrainCells; ++i) {
            const uint32_t a = uint32_t(j * (kTerrainCells + 1) + i), b = a + 1, c = a + kTerrainCells + 1, d = c + 1;
            ground.add_triangle(a, c, b);  // wound so the normal points up (+Y)
            ground.add_triangle(b, c, d);
        }
    return ground;
}

/// A blade: a tapering strip of three triangles leaning by a random bend, facing a random way.
void add_blade(TriangleSoup& grass, Rng& rng, uint64_t seed) {
    const float x = -kTerrainHalf + 2 * kTerrainHalf * rng.next(), z = -kTerrainHalf + 2 * kTerrainHalf * rng.next();
    const float tall = 0.4f + 0.5f * rng.next(), width = 0.05f + 0.03f * rng.next();
    const float turn = float(2 * kPi) * rng.next(), lean = 0.15f + 0.35f * rng.next();
    const Vec3 across(std::cos(turn), 0.0f, std::sin(turn)), bend(-across.z, 0.0f, across.x);
    const Vec3 root(x, height(x, z, seed) - 0.02f, z);  // just below the ground: no gap at the root
    auto at = [&](float s, float side) {
        const float w = width * (1.0f - s);  // tapers to the tip
        return root + Vec3(0.0f, tall * s, 0.0f) + bend * (lean * tall * s * s) + across * (w * side);
    };
    const uint32_t l0 = grass.add_vertex(at(0.0f, -1)), r0 = grass.add_vertex(at(0.0f, 1));
    const uint32_t l1 = grass.add_vertex(at(0.5f, -1)), r1 = grass.add_vertex(at(0.5f, 1));
    const uint32_t tip = grass.add_vertex(at(1.0f, 0));
    grass.add_triangle(l0, r0, r1);
    grass.add_triangle(l0, r1, l1);
    grass.add_triangle(l1, r1, tip);
}

/// A card: an upright quad at a random place and yaw, its foot just below the ground.
void add_card(TriangleSoup& cards, Rng& rng, uint64_t seed) {
    const float x = -kTerrainHalf + 2 * kTerrainHalf * rng.next(), z = -kTerrainHalf + 2 * kTerrainHalf * rng.next();
    const float tall = 0.4f + 0.3f * rng.next(), half = 0.25f + 0.15f * rng.next();
    const float turn = float(2 * kPi) * rng.next();
    const Vec3 across(std::cos(turn) * half, 0.0f, std::sin(turn) * half);
    const Vec3 foot(x, height(x, z, seed) - 0.05f, z), up(0.0f, tall, 0.0f);
    const uint32_t a = cards.add_vertex(foot - across), b = cards.add_vertex(foot + across);
    const uint32_t c = cards.add_vertex(foot + across + up), d = cards.add_vertex(foot - across + up);
    cards.add_triangle(a, b, c);
    cards.add_triangle(a, c, d);
}

/// The hills, their sun and their camera, with `grass` on them in `grass_material`.
std::string write_hills(const std::string& dir, const std::string& name, const TriangleSoup& ground,
                        const TriangleSoup& grass, const Material& grass_material, uint64_t seed) {
    GltfWriter w;
    const int m_ground = w.add_material(make_material("soil", {0.36f, 0.27f, 0.18f}, 0.0f, 0.9f));
    const int m_grass = w.add_material(grass_material);
    const int mesh = w.add_mesh(name, {{&ground, m_ground}, {&grass, m_grass}});
    w.add_mesh_node(name, mesh);
    // A low sun from the south-west: long shadows across the hills and the blades.
    w.add_light("sun", LightType::directional, {0.0f, 50.0f, 0.0f}, {40.0f, 0.0f, 25.0f}, {1.0f, 0.93f, 0.82f}, 3.0f);
    // Standing on a hill edge, looking across the field.
    w.add_camera("camera", {-30.0f, height(-30.0f, -30.0f, seed) + 2.5f, -30.0f}, {10.0f, -2.0f, 10.0f}, 0.9f, 4.0f / 3.0f);
    return w.write(dir, name);
}

}  // namespace

std::string write_meadow(const std::string& dir, const ProceduralOptions& options) {
    const uint64_t seed = hash_combine(options.seed, 0x7e77a1);  // the terrain's hills
    TriangleSoup cards;
    Rng rng(hash_combine(seed, 2));
    for (uint32_t k = 0; k < kMeadowCards; ++k) add_card(cards, rng, seed);
    Material grass = make_material("grass cards", {0.20f, 0.42f, 0.12f}, 0.0f, 0.7f);
    grass.alpha_mode = AlphaMode::mask;
    grass.alpha_coverage = kMeadowCoverage;
    return write_hills(dir, "meadow", height_field(seed), cards, grass, seed);
}

std::string write_terrain(const std::string& dir, const ProceduralOptions& options) {
    const uint64_t seed = hash_combine(options.seed, 0x7e77a1);
    const TriangleSoup ground = height_field(seed);
    TriangleSoup grass;
    Rng rng(hash_combine(seed, 1));
    for (uint32_t b = 0; b < kTerrainBlades; ++b) add_blade(grass, rng, seed);

    return write_hills(dir, "terrain", ground, grass, make_material("grass", {0.20f, 0.42f, 0.12f}, 0.0f, 0.7f), seed);
}

}  // namespace rtsim
