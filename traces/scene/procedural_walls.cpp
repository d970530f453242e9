// Rotated walls: a room of thin walls turned by non-axis-aligned angles about the vertical and some
// tilted, the case where axis-aligned boxes fit badly (the motivation for oriented or split
// bounding volumes, e.g. Ernst & Greiner 2007 "Early Split Clipping"; Stich et al. 2009 SBVH).
// Aligned walls: its unrotated twin, the same maze with every wall on the axes and none tilted,
// where axis-aligned boxes and split planes fit exactly (the case kd-trees are built for).
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "traces/common/rng.h"
#include "traces/scene/procedural_shapes.h"

namespace rtsim {

namespace {

constexpr double kAngles[] = {7.0, 30.0, 45.0, 60.0, 15.0, 75.0, 22.5, 52.0};
constexpr float kHalf = 20.0f;   ///< half size of the room
constexpr int kCells = 10;       ///< maze grid cells per side (4 m apart)
constexpr float kHeight = 2.5f;  ///< wall height

/// A wall box: centre on the floor, length, vertical angle (degrees), tilt about its length; the
/// whole room turned by `room` degrees.
glm::dmat4 wall(double room, double x, double z, double yaw, double tilt, double length, double thickness) {
    glm::dmat4 m = glm::rotate(glm::dmat4(1.0), glm::radians(room), glm::dvec3(0, 1, 0));  // whole room
    m = glm::translate(m, glm::dvec3(x, 0.0, z));
    m = glm::rotate(m, glm::radians(yaw), glm::dvec3(0, 1, 0));
    m = glm::rotate(m, glm::radians(tilt), glm::dvec3(1, 0, 0));
    m = glm::translate(m, glm::dvec3(0.0, kHeight / 2, 0.0));
    return glm::scale(m, glm::dvec3(length, kHeight, thickness));
}

/// The maze, rotated or its axis-aligned twin (the same random draws, so the same walls).
std::string write_walls(const std::string& dir, const ProceduralOptions& options, bool rotated, const char* name) {
    TriangleSoup floor, walls, mirror;
    // Floor and outer walls, the whole room turned by 7 degrees (or not at all).
    const double turn = rotated ? 7.0 : 0.0;
    glm::dmat4 room = glm::rotate(glm::dmat4(1.0), glm::radians(turn), glm::dvec3(0, 1, 0));
    auto at = [&](float x, float z) { return Vec3(room * glm::dvec4(x, 0.0, z, 1.0)); };
    floor.add_quad(at(-kHalf, -kHalf), at(kHalf, -kHalf), at(kHalf, kHalf), at(-kHalf, kHalf), {0, 1, 0});
    for (int side = 0; side < 4; ++side) {
        double yaw = 90.0 * side, rad = glm::radians(yaw);
        walls.add_box(wall(turn, kHalf * std::sin(rad), kHalf * std::cos(rad), yaw, 0.0, 2 * kHalf, 0.2));
    }

    // Inner maze: one candidate wall per cell of the grid (80% kept), jittered.
    int placed = 0;
    for (int i = 0; i < kCells; ++i)
        for (int j = 0; j < kCells; ++j) {
            Rng rng(hash_combine(options.seed, 0x77616c6cull /*"wall"*/, uint64_t(i * kCells + j)));
            if (rng.next() > 0.8f) continue;
            double x = 4.0 * (i - (kCells - 1) / 2.0) + (rng.next() - 0.5);
            double z = 4.0 * (j - (kCells - 1) / 2.0) + (rng.next() - 0.5);
            const size_t angle = size_t(rng.next() * 8.0f) % 8;
            double yaw = rotated ? kAngles[angle] : 90.0 * double(angle % 2);
            double tilt = (placed % 4 == 3) ? 12.0 + 13.0 * rng.next() : 0.0;
            if (!rotated) tilt = 0.0;
            double length = 2.5 + rng.next();
            // The first wall is a mirror so the scene calls for reflection rays.
            (placed == 0 ? mirror : walls).add_box(wall(turn, x, z, yaw, tilt, length, 0.08));
            ++placed;
        }

    GltfWriter w;
    int m_floor = w.add_material(make_material("floor", {0.6f, 0.55f, 0.5f}, 0.0f, 0.9f));
    int m_wall = w.add_material(make_material("plaster", {0.8f, 0.8f, 0.78f}, 0.0f, 0.8f));
    int m_mirror = w.add_material(make_material("mirror", {0.95f, 0.95f, 0.95f}, 1.0f, 0.05f));
    w.add_mesh_node("room", w.add_mesh("room", {{&floor, m_floor}, {&walls, m_wall}, {&mirror, m_mirror}}));
    w.add_light("ceiling_light", LightType::point, {0.0f, 3.2f, 0.0f}, {0, 0, 0}, {1, 1, 1}, 80.0f);
    w.add_camera("camera", at(-17.0f, -17.0f) + Vec3(0, 3.5f, 0), {0.0f, 1.0f, 0.0f}, 0.9f, 1.0f);
    return w.write(dir, name);
}

}  // namespace

std::string write_rotated_walls(const std::string& dir, const ProceduralOptions& options) {
    return write_walls(dir, options, true, "rotated_walls");
}

std::string write_aligned_walls(const std::string& dir, const ProceduralOptions& options) {
    return write_walls(dir, options, false, "aligned_walls");
}

}  // namespace rtsim
