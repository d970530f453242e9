// Animated frames of a two-level structure (docs/accel.md, "Frames"): the motion, one image with
// a TLAS per frame over BLASes built once, each bound frame tracing as the one-frame image of
// its pose, and the frame slices validated.
#include <cstring>
#include <functional>

#include <glm/gtc/matrix_transform.hpp>

#include "accel_test_util.h"
#include "traces/accel/two_level/two_level.h"
#include "traces/common/error.h"
#include "traces/scene/scene.h"
#include "traces/scene/scene_motion.h"

namespace rtsim::test {
namespace {

/// A 3 x 3 grid of two shared meshes plus one mesh placed once (a "ground" that must not move).
Scene grid_scene() {
    Scene s;
    s.source = "frames test scene";
    s.materials = {Material{}};
    s.meshes = {soup_mesh(1, 40), soup_mesh(2, 30), soup_mesh(3, 10)};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            s.instances.push_back(Instance{uint32_t((i + j) % 2),
                                           glm::translate(glm::dmat4(1.0), glm::dvec3(3.0 * i, 0.0, 3.0 * j)), 0, -1});
    s.instances.push_back(Instance{2, glm::scale(glm::dmat4(1.0), glm::dvec3(8.0, 0.1, 8.0)), 0, -1});
    s.index_instances();
    return s;
}

SceneMotion motion_of(const Scene& s) { return scene_motion(s, {true, true, false}); }

std::vector<glm::dmat4> pose(const Scene& s, const SceneMotion& m, uint32_t frame) {
    std::vector<glm::dmat4> out;
    for (uint32_t i = 0; i < s.instances.size(); ++i) out.push_back(animated_transform(m, i, frame));
    return out;
}

AccelOptions options() {
    AccelOptions o;
    o.two_level = true;
    return o;
}

TEST(TwoLevelFrames, MotionRestsAtFrameZeroAndMovesOnlySharedGeometry) {
    const Scene s = grid_scene();
    const SceneMotion m = motion_of(s);
    for (uint32_t i = 0; i < s.instances.size(); ++i) EXPECT_EQ(animated_transform(m, i, 0), s.instances[i].object_to_world);
    EXPECT_EQ(animated_transform(m, 9, 5), s.instances[9].object_to_world);  // the mesh placed once
    EXPECT_NE(animated_transform(m, 0, 1), s.instances[0].object_to_world);
    // 32 frames are a full turn; the bob (16-frame period) is back at rest too.
    const glm::dmat4 turn = animated_transform(m, 3, 32), rest = s.instances[3].object_to_world;
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) EXPECT_NEAR(turn[c][r], rest[c][r], 1e-9);
}

TEST(TwoLevelFrames, FrameZeroIsTheOneFrameImageAndBlasesAreShared) {
    const Scene s = grid_scene();
    const SceneMotion m = motion_of(s);
    TwoLevelTiming timing;
    const AccelImage animated = build_two_level_frames(s, options(), {pose(s, m, 0), pose(s, m, 1), pose(s, m, 2)}, &timing);
    const AccelImage still = build_two_level(s, options());
    EXPECT_EQ(timing.tlas_ms.size(), 3u);
    ASSERT_EQ(animated.params.at("frames").size(), 3u);
    for (const char* name : {"tlas_nodes", "instances"}) {
        const Region &a = animated.region(name), &b = still.region(name);
        EXPECT_EQ(a.count, 3 * b.count) << name;  // one instance per leaf: the same size every frame
        EXPECT_EQ(std::memcmp(a.bytes.data(), b.bytes.data(), b.size_bytes()), 0) << name;
    }
    for (const Region& r : still.regions)
        if (r.name.rfind("blas_", 0) == 0) {
            const Region& a = animated.region(r.name);
            EXPECT_EQ(a.size_bytes(), r.size_bytes());
            EXPECT_EQ(std::memcmp(a.bytes.data(), r.bytes.data(), r.size_bytes()), 0) << r.name;
        }
}

TEST(TwoLevelFrames, EachBoundFrameTracesAsTheOneFrameImageOfItsPose) {
    Scene s = grid_scene();
    const SceneMotion m = motion_of(s);
    const uint32_t frames = 4;
    std::vector<std::vector<glm::dmat4>> poses;
    for (uint32_t f = 0; f < frames; ++f) poses.push_back(pose(s, m, f));
    const std::unique_ptr<Accel> animated = load_accel(build_two_level_frames(s, options(), poses, nullptr), "frames");
    ASSERT_EQ(animated->frame_count(), frames);
    const Region& tlas = animated->image().region("tlas_nodes");
    const uint64_t per_frame = tlas.count / frames;
    for (uint32_t f = 0; f < frames; ++f) {
        pose_scene(s, m, f);
        const std::unique_ptr<Accel> still = load_accel(build_two_level(s, options()), "still");
        animated->bind_frame(f);
        std::unique_ptr<Stepper> step = animated->make_stepper();
        Rng rng(10 + f);
        int hits = 0;
        for (int i = 0; i < 300; ++i) {
            // Rays straight down onto the grid (most hit an instance or the ground), half random.
            Ray r = random_ray(rng, s.bounds, nullptr, 0);
            if (i % 2 == 0) {
                r.origin = random_point(rng, s.bounds.lo, s.bounds.hi);
                r.origin.y = s.bounds.hi.y + 1.0f;
                r.direction = Vec3(0.1f * (rng.next() - 0.5f), -1.0f, 0.1f * (rng.next() - 0.5f));
                r.tmin = 0.0f;
                r.tmax = 1e30f;
            }
            WorkCounts wa, ws;
            const Hit a = trace_with_stepper(*step, r, TraversalMode::closest_hit, &wa);
            const Hit b = still->trace(r, TraversalMode::closest_hit, &ws);
            ASSERT_EQ(a.prim, b.prim) << "frame " << f << " ray " << i;
            ASSERT_EQ(a.inst, b.inst);
            ASSERT_EQ(std::memcmp(&a.t, &b.t, sizeof(float)), 0);
            ASSERT_EQ(wa.steps, ws.steps);
            ASSERT_EQ(wa.transforms, ws.transforms);
            hits += a.valid();
        }
        EXPECT_GT(hits, 5) << "frame " << f;  // not vacuous: the soups are sparse
        // The first step fetches the bound frame's TLAS root, at that frame's own address.
        step->begin(Ray{s.bounds.lo - Vec3(1.0f), 0.0f, Vec3(1.0f), 1e30f}, TraversalMode::closest_hit);
        EXPECT_EQ(step->plan().fetch[0].addr, tlas.address(f * per_frame));
        EXPECT_EQ(step->plan().locality, uint32_t(f * per_frame));
    }
    EXPECT_THROW(animated->bind_frame(frames), Error);
    EXPECT_EQ(animated->partition(1024).group_of.size() >= tlas.count, true);
}

TEST(TwoLevelFrames, ValidationNamesTheFrame) {
    const Scene s = grid_scene();
    const SceneMotion m = motion_of(s);
    AccelImage image = build_two_level_frames(s, options(), {pose(s, m, 0), pose(s, m, 1)}, nullptr);
    image.params["frames"][1]["tlas_first"] = image.region("tlas_nodes").count;
    const std::string msg = error_of([&] { load_accel(std::move(image), "bad.rtt"); });
    EXPECT_NE(msg.find("frame 1"), std::string::npos) << msg;
    EXPECT_NE(msg.find("outside tlas_nodes"), std::string::npos) << msg;
}

}  // namespace
}  // namespace rtsim::test
