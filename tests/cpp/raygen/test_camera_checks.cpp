// Cameras that would make invalid rays: check_camera, check_scene_reach and
// automatic framing of scenes far from the origin, very wide, or of zero extent.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "tests/cpp/error_of.h"
#include "tests/cpp/bvh/bvh_test_scenes.h"
#include "traces/accel/accel.h"
#include "traces/common/error.h"
#include "traces/raygen/auto_framing.h"
#include "traces/raygen/camera.h"

namespace rtsim {
namespace {

using test::error_of;

/// A one-triangle scene spanning `size` around `offset` (as a loader would flatten it).
Scene triangle_at(float offset, float size) {
    Scene s = test::make_scene({Triangle{Vec3(offset - size, offset, offset), Vec3(offset + size, offset, offset),
                                         Vec3(offset, offset + size, offset + 1e-3f * size)}});
    s.source = "far.glb";
    return s;
}

/// Automatic framing, then the camera checks the tracer makes: "" if every check passes.
std::string frame_and_check(const Scene& scene) {
    return error_of([&] {
        AccelOptions options;
        const std::unique_ptr<Accel> accel = load_accel(build_accel(scene, options), "far.glb");
        PinholeCamera cam = make_camera(auto_frame(scene, *accel, 4.0f / 3.0f, nullptr), 64, 48);
        check_camera(cam, "far.glb: camera");
        check_scene_reach(cam, scene.bounds, "far.glb: camera");
        for (uint32_t y = 0; y < 48; y += 47)
            for (uint32_t x = 0; x < 64; x += 63)
                if (!ray_is_valid(primary_ray(cam, x, y, 64, 48))) throw Error("invalid primary ray");
    });
}

TEST(CameraChecks, InvalidCamerasRefused) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    PinholeCamera ok = make_camera(look_at(Vec3(0, 0, 5), Vec3(0.0f), 60.0f), 64, 48);
    EXPECT_EQ(error_of([&] { check_camera(ok, "s.gltf"); }), "");
    PinholeCamera bad = ok;
    bad.eye.x = std::numeric_limits<float>::infinity();
    EXPECT_NE(error_of([&] { check_camera(bad, "s.gltf"); }).find("s.gltf: camera eye (inf"), std::string::npos);
    bad = make_camera(look_at(Vec3(1, 2, 3), Vec3(1, 2, 3), 60.0f), 64, 48);  // eye == target
    EXPECT_NE(error_of([&] { check_camera(bad, "s.gltf"); }).find("no valid view direction"), std::string::npos);
    bad = ok;
    bad.tan_half_fov = nan;
    EXPECT_NE(error_of([&] { check_camera(bad, "s.gltf"); }).find("field of view"), std::string::npos);
}

TEST(CameraChecks, FarAndWideScenesFramedOrRefused) {
    // Near the origin, 1e6 away and 1e15 wide: framed, every corner ray valid.
    EXPECT_EQ(frame_and_check(triangle_at(0.0f, 1.0f)), "");
    EXPECT_EQ(frame_and_check(triangle_at(1e6f, 1.0f)), "");
    EXPECT_EQ(frame_and_check(triangle_at(0.0f, 1e15f)), "");
    // 1e30 away or 1e20 wide: the eye-to-geometry distances overflow the float ray/triangle
    // test, so the trace would be all misses: refused, naming the file.
    for (const Scene& s : {triangle_at(1e30f, 1e24f), triangle_at(0.0f, 1e20f)}) {
        std::string msg = frame_and_check(s);
        EXPECT_NE(msg.find("far.glb"), std::string::npos) << msg;
        EXPECT_NE(msg.find("overflow"), std::string::npos) << msg;
    }
    // Bounds beyond the float range, and a scene that is a single point.
    std::string huge = frame_and_check(triangle_at(0.0f, 3e38f));
    EXPECT_NE(huge.find("far.glb: automatic framing failed"), std::string::npos) << huge;
    std::string point = frame_and_check(triangle_at(1.0f, 0.0f));
    EXPECT_NE(point.find("zero extent"), std::string::npos) << point;
}

}  // namespace
}  // namespace rtsim
