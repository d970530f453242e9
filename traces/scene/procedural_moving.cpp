// The procedural deforming scenes: a waving cloth over a floor and an exploding hairball. Their
// motion is analytic (procedural_motion.h), stored in the glTF mesh's extras so the loader gives
// the scene its Scene::animation; frame 0 is the rest pose written here.
#include <cmath>

#include "traces/common/error.h"
#include "traces/common/rng.h"
#include "traces/scene/procedural_shapes.h"
#include "traces/scene/scene.h"

namespace rtsim {

namespace {

constexpr int kClothCells = 128;        ///< cells per side: 2 x 128^2 = 32768 triangles
constexpr float kClothSize = 2.0f;      ///< metres per side
constexpr float kClothHeight = 0.8f;    ///< above the floor (metres)
constexpr uint32_t kExplodingHairs = 20000;  ///< triangles of the exploding hairball

}  // namespace

std::string write_cloth(const std::string& dir, const ProceduralOptions& options) {
    (void)options;
    TriangleSoup cloth, floor;
    const float h = kClothSize / kClothCells, x0 = -0.5f * kClothSize;
    for (int j = 0; j <= kClothCells; ++j)
        for (int i = 0; i <= kClothCells; ++i)
            cloth.add_vertex({x0 + i * h, kClothHeight, x0 + j * h});
    const uint32_t row = kClothCells + 1;
    for (uint32_t j = 0; j < uint32_t(kClothCells); ++j)
        for (uint32_t i = 0; i < uint32_t(kClothCells); ++i) {
            uint32_t a = j * row + i;
            // Wound so the face normal points up (+y), towards camera and light.
            cloth.add_triangle(a, a + row, a + 1);
            cloth.add_triangle(a + 1, a + row, a + row + 1);
        }
    floor.add_quad({-3, 0, -3}, {3, 0, -3}, {3, 0, 3}, {-3, 0, 3}, {0, 1, 0});

    GltfWriter w;
    int m_cloth = w.add_material(make_material("cloth", {0.7f, 0.15f, 0.12f}, 0.0f, 0.8f));
    int m_floor = w.add_material(make_material("floor", {0.6f, 0.6f, 0.6f}, 0.0f, 1.0f));
    int cloth_mesh = w.add_mesh("cloth", {{&cloth, m_cloth}});
    ProceduralMotion wave;
    wave.kind = ProceduralMotion::Kind::wave;
    wave.amplitude = 0.25f;
    wave.wavelength = 0.8f;
    wave.period = 1.0f;
    wave.x_pinned = x0;  // the -x edge hangs still, as if held
    wave.extent = kClothSize;
    w.set_mesh_motion(cloth_mesh, wave);
    w.add_mesh_node("cloth", cloth_mesh);
    w.add_mesh_node("floor", w.add_mesh("floor", {{&floor, m_floor}}));
    w.add_light("sun", LightType::directional, {2.0f, 4.0f, 1.5f}, {0, 0, 0}, {1, 1, 1}, 3.0f);
    w.add_camera("camera", {0.0f, 2.6f, 3.4f}, {0.0f, 0.5f, 0.0f}, 0.8f, 1.0f);
    return w.write(dir, "cloth");
}

std::string write_exploding_hairball(const std::string& dir, const ProceduralOptions& options) {
    // The hairball's strands, fewer of them (the scene is retraced every frame).
    TriangleSoup hair = hairball_strands(kExplodingHairs, options.seed), floor;
    floor.add_quad({-6, -1.2f, -6}, {6, -1.2f, -6}, {6, -1.2f, 6}, {-6, -1.2f, 6}, {0, 1, 0});

    GltfWriter w;
    int m_hair = w.add_material(make_material("hair", {0.45f, 0.3f, 0.18f}, 0.0f, 0.6f));
    int m_floor = w.add_material(make_material("floor", {0.6f, 0.6f, 0.6f}, 0.0f, 1.0f));
    int hair_mesh = w.add_mesh("exploding_hairball", {{&hair, m_hair}});
    ProceduralMotion scatter;
    scatter.kind = ProceduralMotion::Kind::scatter;
    scatter.center = Vec3(0.0f);
    scatter.speed_min = 0.2f;  // over 60 frames (1 s) the ball grows to about 2-3x its radius
    scatter.speed_max = 2.0f;
    scatter.seed = options.seed;
    w.set_mesh_motion(hair_mesh, scatter);
    w.add_mesh_node("exploding_hairball", hair_mesh);
    w.add_mesh_node("floor", w.add_mesh("floor", {{&floor, m_floor}}));
    w.add_light("key_light", LightType::point, {2.5f, 3.0f, 2.5f}, {0, 0, 0}, {1, 1, 1}, 60.0f);
    w.add_camera("camera", {0.0f, 0.6f, 5.0f}, {0, 0, 0}, 0.9f, 1.0f);
    return w.write(dir, "exploding_hairball");
}

}  // namespace rtsim
