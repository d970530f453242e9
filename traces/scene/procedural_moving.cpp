// The procedural deforming scenes: a waving cloth over a floor and an exploding hairball, whose
// motion is analytic (procedural_motion.h), stored in the glTF mesh's extras so the loader gives
// the scene its Scene::animation (frame 0 is the rest pose written here); and a skinned tube, a
// glTF skin with a joint chain and its animation channels, read back through the loader's own
// skinning path like a skinned character of a real file.
#include <algorithm>
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
constexpr int kTubeSides = 48, kTubeRings = 128;  ///< 2 x 48 x 128 = 12288 triangles
constexpr int kTubeJoints = 8;                    ///< a chain along the tube
constexpr float kTubeLength = 2.0f, kTubeRadius = 0.12f;
constexpr int kTubeKeys = 61;             ///< keys over one period, the last equal to the first
constexpr float kTubePeriod = 2.0f;       ///< seconds per sway (the loader loops the animation)
constexpr float kTubeBend = 0.22f;        ///< radians per joint at the sway's peak

/// Joint k of the tube's chain at time t: a sway about z travelling up the chain, and half as much
/// about x a quarter period later, so the tube bends in both directions.
glm::quat tube_joint_rotation(int k, float t) {
    const float phase = float(2.0 * kPi) * t / kTubePeriod - 0.6f * float(k);
    const float about_z = kTubeBend * std::sin(phase), about_x = 0.5f * kTubeBend * std::cos(phase);
    return glm::angleAxis(about_z, glm::vec3(0, 0, 1)) * glm::angleAxis(about_x, glm::vec3(1, 0, 0));
}

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
    // Over 60 frames (1 s) the ball grows to about 2-3x its radius.
    w.set_mesh_motion(hair_mesh, scatter_motion(0.2f, 2.0f, options.seed));
    w.add_mesh_node("exploding_hairball", hair_mesh);
    w.add_mesh_node("floor", w.add_mesh("floor", {{&floor, m_floor}}));
    w.add_light("key_light", LightType::point, {2.5f, 3.0f, 2.5f}, {0, 0, 0}, {1, 1, 1}, 60.0f);
    w.add_camera("camera", {0.0f, 0.6f, 5.0f}, {0, 0, 0}, 0.9f, 1.0f);
    return w.write(dir, "exploding_hairball");
}

std::string write_skinned_tube(const std::string& dir, const ProceduralOptions& options) {
    (void)options;
    // An open tube along +y, its vertices weighted to the two joints around their height.
    TriangleSoup tube, floor;
    SkinWeights weights;
    const float bone = kTubeLength / kTubeJoints;
    for (int r = 0; r <= kTubeRings; ++r) {
        const float y = kTubeLength * float(r) / kTubeRings;
        const float s = std::min(y / bone, float(kTubeJoints - 1) + 0.999f);
        const int j = int(s);
        const float f = s - float(j);
        for (int k = 0; k < kTubeSides; ++k) {
            const double a = 2.0 * kPi * k / kTubeSides;
            tube.add_vertex({kTubeRadius * float(std::cos(a)), y, kTubeRadius * float(std::sin(a))});
            const bool last = j + 1 >= kTubeJoints;
            weights.joints.push_back(glm::u16vec4(j, last ? j : j + 1, 0, 0));
            weights.weights.push_back(last ? glm::vec4(1, 0, 0, 0) : glm::vec4(1.0f - f, f, 0, 0));
        }
    }
    for (uint32_t r = 0; r < uint32_t(kTubeRings); ++r)
        for (uint32_t k = 0; k < uint32_t(kTubeSides); ++k) {
            const uint32_t a = r * kTubeSides + k, b = r * kTubeSides + (k + 1) % kTubeSides;
            // Wound so the face normal points out of the tube.
            tube.add_triangle(a, b + kTubeSides, b);
            tube.add_triangle(a, a + kTubeSides, b + kTubeSides);
        }
    floor.add_quad({-3, 0, -3}, {3, 0, -3}, {3, 0, 3}, {-3, 0, 3}, {0, 1, 0});

    Skeleton skeleton;
    for (int t = 0; t < kTubeKeys; ++t) skeleton.key_times.push_back(kTubePeriod * float(t) / float(kTubeKeys - 1));
    for (int k = 0; k < kTubeJoints; ++k) {
        SkinJoint joint{"joint" + std::to_string(k), k - 1, Vec3(0.0f, k == 0 ? 0.0f : bone, 0.0f), {}};
        for (float t : skeleton.key_times) joint.rotations.push_back(tube_joint_rotation(k, t));
        skeleton.joints.push_back(joint);
    }

    GltfWriter w;
    int m_tube = w.add_material(make_material("tube", {0.2f, 0.5f, 0.25f}, 0.0f, 0.5f));
    int m_floor = w.add_material(make_material("floor", {0.6f, 0.6f, 0.6f}, 0.0f, 1.0f));
    w.add_skinned_mesh_node("skinned_tube", tube, m_tube, weights, skeleton);
    w.add_mesh_node("floor", w.add_mesh("floor", {{&floor, m_floor}}));
    w.add_light("sun", LightType::directional, {2.0f, 4.0f, 3.0f}, {0, 0, 0}, {1, 1, 1}, 3.0f);
    w.add_camera("camera", {0.0f, 1.1f, 4.2f}, {0.0f, 1.0f, 0.0f}, 0.8f, 1.0f);
    return w.write(dir, "skinned_tube");
}

}  // namespace rtsim
