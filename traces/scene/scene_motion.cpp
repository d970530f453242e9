// The motion of animated frames (scene_motion.h).
#include "traces/scene/scene_motion.h"

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "traces/common/error.h"

namespace rtsim {

namespace {

constexpr double kTwoPi = 6.283185307179586;
constexpr double kSpinFrames = 32.0;    ///< frames per full turn
constexpr double kBobFrames = 16.0;     ///< frames per bob period
constexpr double kBobHeight = 0.05;     ///< bob amplitude, fraction of the instance's height
constexpr double kGolden = 0.6180339887498949;

}  // namespace

SceneMotion scene_motion(const Scene& scene, const std::vector<bool>& moving_mesh) {
    SceneMotion m;
    std::vector<Aabb> mesh_box(scene.meshes.size());
    for (size_t k = 0; k < scene.meshes.size(); ++k)
        for (const Vec3& p : scene.meshes[k].positions) mesh_box[k].grow(p);
    for (const Instance& inst : scene.instances) {
        m.rest.push_back(inst.object_to_world);
        m.moves.push_back(inst.mesh < moving_mesh.size() && moving_mesh[inst.mesh]);
        glm::dvec3 lo(INFINITY), hi(-INFINITY);
        const Aabb& b = mesh_box[inst.mesh];
        for (int c = 0; !b.empty() && c < 8; ++c) {
            const glm::dvec4 p(c & 1 ? b.hi.x : b.lo.x, c & 2 ? b.hi.y : b.lo.y, c & 4 ? b.hi.z : b.lo.z, 1.0);
            const glm::dvec3 w(inst.object_to_world * p);
            lo = glm::min(lo, w);
            hi = glm::max(hi, w);
        }
        m.centre.push_back(b.empty() ? glm::dvec3(0.0) : 0.5 * (lo + hi));
        m.height.push_back(b.empty() ? 0.0 : hi.y - lo.y);
    }
    return m;
}

glm::dmat4 animated_transform(const SceneMotion& motion, uint32_t i, uint32_t frame) {
    if (frame == 0 || !motion.moves[i]) return motion.rest[i];  // the rest pose, bit for bit
    const double f = double(frame);
    const double spin = (i % 2 == 0 ? 1.0 : -1.0) * f * kTwoPi / kSpinFrames;
    const double phi = kTwoPi * (kGolden * double(i) - std::floor(kGolden * double(i)));
    const double bob = kBobHeight * motion.height[i] * (std::sin(kTwoPi * f / kBobFrames + phi) - std::sin(phi));
    const glm::dvec3 c = motion.centre[i];
    glm::dmat4 m = glm::translate(glm::dmat4(1.0), c + glm::dvec3(0.0, bob, 0.0));
    m = glm::rotate(m, spin, glm::dvec3(0.0, 1.0, 0.0));
    m = glm::translate(m, -c);
    return m * motion.rest[i];
}

void pose_scene(Scene& scene, const SceneMotion& motion, uint32_t frame) {
    require(motion.rest.size() == scene.instances.size(), scene.source + ": motion of another scene");
    for (uint32_t i = 0; i < scene.instances.size(); ++i)
        scene.instances[i].object_to_world = animated_transform(motion, i, frame);
    scene.index_instances();
}

const char* motion_description() {
    return "instances of shared geometry spin about their own up (+Y) axis through their box centre, "
           "11.25 degrees a frame (even instance ids counter-clockwise, odd clockwise), and bob by "
           "5% of their height with a 16-frame period and a per-instance phase; frame 0 is the rest pose, "
           "instances placed once stay still (docs/accel.md, Frames)";
}

}  // namespace rtsim
