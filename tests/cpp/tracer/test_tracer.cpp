// End-to-end tests of the reference tracer: scene in, trace folder out, and the trace agrees
// with a re-trace of its own rays.
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "traces/bvh/builder.h"
#include "traces/common/error.h"
#include "traces/format/trace_reader.h"
#include "traces/accel/accel_io.h"
#include "traces/accel/bvh2/bvh2.h"
#include "traces/raygen/workload.h"
#include "traces/scene/gltf_loader.h"
#include "traces/tracer/ray_trace.h"
#include "traces/tracer/tracer.h"
#include "tests/cpp/process_temp_dir.h"

namespace fs = std::filesystem;
using namespace rtsim;

namespace {

fs::path temp_dir(const std::string& name) {
    fs::path p = test::process_temp_dir("tracer") / name;
    fs::remove_all(p);
    return p;
}

std::string scenes_dir() {
    const char* env = std::getenv("RTSIM_SCENES");
    return env ? env : RTSIM_SCENES_DIR;
}

const std::vector<RayKind> kAllKinds = {RayKind::primary, RayKind::shadow, RayKind::reflection, RayKind::diffuse,
                                        RayKind::refraction};

TraceOptions small_options(const std::string& scene, const fs::path& out) {
    TraceOptions o;
    o.scene = scene;
    o.out_dir = out.string();
    o.workload = kAllKinds;
    o.width = 48;
    o.height = 32;
    o.bounces = 2;
    o.procedural.hairball_triangles = 20000;
    return o;
}

/// Re-traces every ray of a trace with the BVH image stored in it: hits and work must be
/// bit-identical to the recorded reference.
void expect_trace_self_consistent(const fs::path& trace) {
    TraceReader reader(trace.string());
    const std::unique_ptr<Accel> accel = load_accel(read_accel_image(reader), trace.string());
    auto rays = reader.read_all<RayRecord>(SectionKind::rays);
    auto hits = reader.read_all<HitRecord>(SectionKind::hits);
    auto work = reader.read_all<WorkRecord>(SectionKind::work);
    ASSERT_EQ(rays.size(), hits.size());
    ASSERT_EQ(rays.size(), work.size());
    for (size_t i = 0; i < rays.size(); ++i) {
        WorkCounts w;
        TraversalMode mode = (rays[i].flags & kRayFlagAnyHit) ? TraversalMode::any_hit : TraversalMode::closest_hit;
        Hit h = accel->trace(ray_from_record(rays[i]), mode, &w);
        ASSERT_EQ(h.prim, hits[i].prim) << "ray " << i;
        ASSERT_EQ(std::memcmp(&h.t, &hits[i].t, 4), 0) << "ray " << i;
        ASSERT_EQ(w.traced(), work[i].counts()) << "ray " << i;  // a trace holds no model-only counts
    }
}

const nlohmann::json& effect(const nlohmann::json& manifest, const std::string& name) {
    for (const auto& e : manifest["workload"]["effects"])
        if (e["name"] == name) return e;
    throw std::runtime_error("no effect " + name);
}

}  // namespace

TEST(Tracer, ProceduralScenesTraceAndReplay) {
    for (const std::string& name : procedural_scene_names()) {
        SCOPED_TRACE(name);
        fs::path out = temp_dir(name);
        nlohmann::json m = trace_scene(small_options(name, out));
        EXPECT_TRUE(fs::exists(out / "trace.rtt"));
        EXPECT_TRUE(fs::exists(out / "manifest.json"));
        EXPECT_TRUE(fs::exists(out / "render.png"));
        EXPECT_GT(m["counts"]["rays"].get<uint64_t>(), 48u * 32u);
        EXPECT_GT(m["counts"]["by_kind"]["primary"]["hits"].get<uint64_t>(), 0u);
        expect_trace_self_consistent(out / "trace.rtt");
        fs::remove_all(out);
    }
}

TEST(Tracer, CornellCallsForShadowsAndReflections) {
    fs::path out = temp_dir("cornell_effects");
    nlohmann::json m = trace_scene(small_options("cornell", out));
    EXPECT_TRUE(effect(m, "shadow")["simulated"].get<bool>());
    EXPECT_TRUE(effect(m, "reflection")["simulated"].get<bool>());
    EXPECT_FALSE(effect(m, "refraction")["simulated"].get<bool>());
    EXPECT_NE(effect(m, "refraction")["why"].get<std::string>().find("transmission"), std::string::npos);
    EXPECT_GT(m["counts"]["by_kind"]["shadow"]["traced"].get<uint64_t>(), 0u);
    fs::remove_all(out);
}

TEST(Tracer, DeterministicWhateverTheThreadCount) {
    fs::path a = temp_dir("det_a"), b = temp_dir("det_b");
    TraceOptions o = small_options("cornell", a);
    o.threads = 1;
    trace_scene(o);
    o.out_dir = b.string();
    o.threads = 2;
    trace_scene(o);
    std::ifstream fa(a / "trace.rtt", std::ios::binary), fb(b / "trace.rtt", std::ios::binary);
    std::string sa((std::istreambuf_iterator<char>(fa)), {}), sb((std::istreambuf_iterator<char>(fb)), {});
    EXPECT_GT(sa.size(), 1000u);
    EXPECT_EQ(sa, sb);
    fs::remove_all(a);
    fs::remove_all(b);
}

TEST(Tracer, OnlyRequestedKindsAreWritten) {
    fs::path out = temp_dir("diffuse_only");
    TraceOptions o = small_options("cornell", out);
    o.workload = {RayKind::diffuse};
    nlohmann::json m = trace_scene(o);
    TraceReader reader((out / "trace.rtt").string());
    for (const RayRecord& r : reader.read_all<RayRecord>(SectionKind::rays)) ASSERT_EQ(r.kind, uint8_t(RayKind::diffuse));
    EXPECT_EQ(m["counts"]["by_kind"]["primary"]["written"].get<uint64_t>(), 0u);
    EXPECT_GT(m["counts"]["rays"].get<uint64_t>(), 0u);
    fs::remove_all(out);
}

TEST(Tracer, BadOptionsNameTheField) {
    TraceOptions o = small_options("cornell", temp_dir("bad"));
    o.width = 0;
    try {
        trace_scene(o);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("resolution"), std::string::npos);
    }
    o = small_options("no_such_scene.gltf", temp_dir("bad2"));
    EXPECT_THROW(trace_scene(o), Error);
}

TEST(Tracer, EverySharedSceneTraces) {
    const std::vector<std::string> scenes = {
        "sponza/Sponza.gltf", "stanford_bunny/bunny.gltf", "LightsPunctualLamp/LightsPunctualLamp.gltf",
        "MetalRoughSpheresNoTextures/MetalRoughSpheresNoTextures.gltf", "AlphaBlendModeTest/AlphaBlendModeTest.gltf",
        "SimpleInstancing/SimpleInstancing.gltf"};
    for (const std::string& s : scenes) {
        fs::path path = fs::path(scenes_dir()) / s;
        if (!fs::exists(path)) GTEST_SKIP() << "shared scenes not found at " << scenes_dir();
        SCOPED_TRACE(s);
        fs::path out = temp_dir(path.stem().string());
        TraceOptions o = small_options(path.string(), out);
        o.bounces = 1;
        nlohmann::json m = trace_scene(o);
        EXPECT_GT(m["counts"]["by_kind"]["primary"]["hits"].get<uint64_t>(), 48u * 32u / 20) << "camera sees little";
        expect_trace_self_consistent(out / "trace.rtt");
        fs::remove_all(out);
    }
}

TEST(Tracer, SharedSceneEffectsFollowTheScene) {
    fs::path lamp = fs::path(scenes_dir()) / "LightsPunctualLamp/LightsPunctualLamp.gltf";
    if (!fs::exists(lamp)) GTEST_SKIP() << "shared scenes not found";
    Scene scene = load_gltf(lamp.string());
    WorkloadPlan plan = plan_workload(scene, kAllKinds);
    EXPECT_TRUE(plan.wants(RayKind::shadow));
    EXPECT_TRUE(plan.wants(RayKind::refraction));
    Scene sponza = load_gltf((fs::path(scenes_dir()) / "sponza/Sponza.gltf").string());
    WorkloadPlan sp = plan_workload(sponza, kAllKinds);
    EXPECT_FALSE(sp.wants(RayKind::shadow));
    EXPECT_TRUE(sp.wants(RayKind::reflection));
    bool alpha = false;
    for (const Effect& e : sp.effects) alpha |= e.name == "alpha_mask" && e.simulated;
    EXPECT_TRUE(alpha);
}

// write_ray_trace writes through the same TraceFolderWriter as trace_scene: the tracer's own
// primary rays, given back as user rays, give a byte-identical trace.rtt.
TEST(Tracer, GivenRaysWriteTheSameTrace) {
    fs::path a = temp_dir("given_a"), b = temp_dir("given_b");
    TraceOptions o = small_options("cornell", a);
    o.workload = {RayKind::primary};
    trace_scene(o);
    TraceReader reader((a / "trace.rtt").string());
    std::vector<PendingRay> rays;
    const std::vector<ShadeRecord> shade = reader.read_all<ShadeRecord>(SectionKind::shading);
    for (const RayRecord& r : reader.read_all<RayRecord>(SectionKind::rays)) {
        PendingRay p;
        p.ray = ray_from_record(r);
        p.pixel = r.pixel;
        // The ray cones the tracer gave its primary rays (given rays carry their own).
        p.cone_width = shade[rays.size()].cone_width;
        p.cone_spread = shade[rays.size()].cone_spread;
        rays.push_back(p);
    }
    Scene scene = load_gltf((a / "scene" / "cornell.gltf").string());
    const std::unique_ptr<Accel> accel = load_accel(build_accel(scene, o.accel));
    RayTraceOptions ro;
    ro.out_dir = b.string();
    nlohmann::json m = write_ray_trace(scene, {"cornell", true}, *accel, rays, ro);
    std::ifstream fa(a / "trace.rtt", std::ios::binary), fb(b / "trace.rtt", std::ios::binary);
    std::string sa((std::istreambuf_iterator<char>(fa)), {}), sb((std::istreambuf_iterator<char>(fb)), {});
    EXPECT_GT(sa.size(), 1000u);
    EXPECT_EQ(sa, sb);
    EXPECT_EQ(m["counts"]["rays"].get<uint64_t>(), rays.size());
    EXPECT_EQ(m["workload"]["requested"], "given");
    EXPECT_TRUE(fs::is_regular_file(b / "manifest.json"));
    EXPECT_THROW(write_ray_trace(scene, {"cornell", true}, *accel, {}, ro), Error);
    fs::remove_all(a);
    fs::remove_all(b);
}
