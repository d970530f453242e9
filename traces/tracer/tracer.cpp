#include "traces/tracer/tracer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <thread>

#include "traces/accel/two_level/two_level.h"
#include "traces/common/error.h"
#include "traces/common/files.h"
#include "traces/common/stopwatch.h"
#include "traces/raygen/added_lights.h"
#include "traces/raygen/auto_framing.h"
#include "traces/raygen/camera.h"
#include "traces/scene/gltf_loader.h"
#include "traces/shading/materials.h"
#include "traces/shading/texels.h"
#include "traces/tracer/frames.h"
#include "traces/tracer/preview_render.h"
#include "traces/tracer/trace_folder.h"
#include "traces/tracer/wavefront.h"
#include "traces/common/build_info.h"

namespace rtsim {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

/// Most placed triangles whose shading records a trace holds (about 1.5 GiB of them).
constexpr uint64_t kMaxShadedTriangles = uint64_t(1) << 25;

/// The camera the user gave, else the scene's first camera, else automatic framing.
Camera choose_camera(const TraceOptions& o, const Scene& scene, const Accel& accel, std::string* source) {
    if (o.camera) {
        *source = "command line";
        return look_at(o.camera->eye, o.camera->target, o.camera->yfov_degrees);
    }
    if (!scene.cameras.empty()) {
        *source = "glTF camera '" + scene.cameras[0].name + "'";
        return scene.cameras[0];
    }
    return auto_frame(scene, accel, float(o.width) / float(o.height), source);
}

/// Every primary ray; an invalid one (NaN or infinite) is refused, never written silently.
std::vector<PendingRay> primary_rays(const PinholeCamera& cam, uint32_t w, uint32_t h, const std::string& source) {
    std::vector<PendingRay> rays(size_t(w) * h);
    const RayCone cone = primary_cone(2.0f * std::atan(cam.tan_half_fov), h);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            PendingRay& r = rays[size_t(y) * w + x];
            r.ray = primary_ray(cam, x, y, w, h);
            require(ray_is_valid(r.ray), source + ": primary ray of pixel (" + std::to_string(x) + ", " +
                                             std::to_string(y) + ") is not finite (camera eye, axes or field of view)");
            r.kind = RayKind::primary;
            r.pixel = y * w + x;
            r.cone_spread = cone.spread;
        }
    return rays;
}

/// Next wavefront: secondaries of every path ray, grouped by kind (stable), so a trace lists
/// depth by depth and, within a depth, shadow, reflection, diffuse, refraction rays.
std::vector<PendingRay> next_wavefront(const SpawnContext& ctx, const std::vector<PendingRay>& rays,
                                       const std::vector<Hit>& hits) {
    std::vector<PendingRay> next;
    for (size_t i = 0; i < rays.size(); ++i) {
        if (rays[i].kind == RayKind::shadow) continue;
        const size_t first = next.size();
        spawn_secondaries(ctx, rays[i], hits[i], i, &next);
        // Each child records its parent and starts its ray cone where the parent's ended.
        const RayCone parent{rays[i].cone_width, rays[i].cone_spread};
        for (size_t c = first; c < next.size(); ++c) {
            const RayCone cone = child_cone(parent, rays[i].ray.direction, hits[i].t, next[c].kind);
            next[c].parent = int64_t(i);
            next[c].cone_width = cone.width;
            next[c].cone_spread = cone.spread;
        }
    }
    std::stable_sort(next.begin(), next.end(),
                     [](const PendingRay& a, const PendingRay& b) { return a.kind < b.kind; });
    return next;
}

std::string resolve_scene(const TraceOptions& o, bool* procedural) {
    *procedural = is_procedural_scene(o.scene);
    if (!*procedural) return o.scene;
    return write_procedural_scene(o.scene, (fs::path(o.out_dir) / "scene").string(), o.procedural);
}

std::string vec_text(const Vec3& v) {
    return "(" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) + ")";
}

/// Checks every option before the scene loads; returns the any-hit child order it parsed.
AnyHitOrder validate(const TraceOptions& o) {
    require(!o.scene.empty(), "no scene given");
    require(!o.out_dir.empty(), "no output folder given");
    require_utf8_path(o.scene, "scene");
    require_utf8_path(o.out_dir, "output folder");
    require(o.width > 0 && o.height > 0 && uint64_t(o.width) * o.height <= (1ull << 28),
            "resolution " + std::to_string(o.width) + "x" + std::to_string(o.height) + " is out of range");
    require(o.bounces <= 64, "bounces " + std::to_string(o.bounces) + " is out of range (0..64)");
    if (o.camera) {
        const CameraOverride& c = *o.camera;
        require(c.yfov_degrees > 0.0f && c.yfov_degrees < 180.0f, "camera field of view must be in (0, 180) degrees");
        const bool finite = std::isfinite(c.eye.x) && std::isfinite(c.eye.y) && std::isfinite(c.eye.z) &&
                            std::isfinite(c.target.x) && std::isfinite(c.target.y) && std::isfinite(c.target.z);
        require(finite, "camera eye and target must be finite single-precision numbers (eye " + vec_text(c.eye) +
                            ", target " + vec_text(c.target) + ")");
        require(c.eye != c.target, "camera eye " + vec_text(c.eye) + " equals the target: no view direction");
    }
    validate_accel_options(o.accel);
    require(known_added_lights(o.lights), "lights: unknown choice '" + o.lights + "' (choose none or sun)");
    require(o.reflections == "mirror" || o.reflections == "glossy",
            "reflections: unknown choice '" + o.reflections + "' (choose mirror or glossy)");
    require(o.roulette_after <= 64, "roulette_after " + std::to_string(o.roulette_after) + " is out of range (0..64)");
    AnyHitOrder order;
    require(parse_anyhit_order(o.anyhit_order, &order),
            "anyhit_order: unknown choice '" + o.anyhit_order + "' (choose nearest, largest_box or fixed)");
    require(o.frames >= 1 && o.frames <= kMaxFrames,
            "frames " + std::to_string(o.frames) + " is out of range (1.." + std::to_string(kMaxFrames) + ")");
    parse_frame_policy(o.frame_policy);  // refuses an unknown one, listing the choices
    require(std::isfinite(o.rebuild_threshold) && o.rebuild_threshold >= 1.0,
            "rebuild_threshold " + std::to_string(o.rebuild_threshold) + " must be at least 1 (a refitted tree's SAH "
            "cost over its rebuilt cost)");
    return order;
}

/// The instancing effect of a two-level trace: simulated (BLASes, TLAS, transform stage).
void mark_instancing_simulated(WorkloadPlan& plan, const AccelImage& image) {
    for (Effect& e : plan.effects) {
        if (e.name != "instancing") continue;
        e.simulated = true;
        e.why = std::to_string(image.stats.value("instances", 0)) + " instances of " +
                std::to_string(image.stats.value("blases", 0)) + " meshes: a " +
                image.stats.value("blas_kind", std::string()) +
                " BLAS per mesh, a TLAS over the instances, a transform stage (--flatten: one world-space structure)";
    }
}

}  // namespace

json trace_scene(const TraceOptions& o, const ProgressFn& progress) {
    StepOptions walk;
    walk.anyhit_order = validate(o);
    auto t_start = std::chrono::steady_clock::now();
    auto report = [&](uint64_t done, uint64_t total, const std::string& stage) {
        if (progress) progress(done, total, stage);
    };
    make_output_folder(o.out_dir, "trace output");

    report(0, 1, "load");
    bool procedural = false;
    std::string path = resolve_scene(o, &procedural);
    // Kept as instances: flattened only for a single-level structure (so an instanced scene too
    // large to flatten still traces two-level).
    Scene scene = load_gltf(path, false);
    const json lights_added = add_lights(scene, o.lights);
    AccelOptions accel_options = o.accel;
    // Deforming geometry is traced two-level too over frames: a BLAS per frame for what moves.
    const bool deforming = o.frames > 1 && has_deforming_geometry(scene);
    accel_options.two_level = !o.flatten && (shares_geometry(scene) || deforming);
    // The build may use the tracing threads too: its image does not depend on their number.
    accel_options.build_threads = o.threads ? o.threads : std::max(1u, std::thread::hardware_concurrency());
    check_frames(o.frames, o.flatten, accel_options.two_level, path);
    if (accel_options.two_level) check_instance_transforms(scene, true);
    if (!accel_options.two_level) scene.flatten();
    double load_ms = ms_since(t_start);
    require(scene.triangle_count() > 0, path + ": the scene has no triangles");

    report(0, 1, "accel");
    // Animated frames: BLASes once, a TLAS per frame (frames.h); else one structure.
    AnimatedImage animated;
    const FramePolicyOptions policy{parse_frame_policy(o.frame_policy), o.rebuild_threshold};
    if (o.frames > 1) animated = build_animated(scene, accel_options, o.frames, policy);
    else animated.image = build_accel(scene, accel_options);
    // Any-hit rays traced in another child order than nearest first: the structure says so (its
    // stats, read back with the trace by the simulator: StructureFacts::traced_anyhit_order).
    if (walk.anyhit_order != AnyHitOrder::nearest) {
        require(accel_capabilities(animated.image.kind, animated.image.params.value("blas_kind", "")).anyhit_order,
                path + ": --anyhit-order " + o.anyhit_order + ": structure '" + animated.image.kind +
                    "' has no any-hit child order (rtsim capabilities)");
        animated.image.stats["anyhit_order"] = o.anyhit_order;
    }
    const std::unique_ptr<Accel> accel = load_accel(std::move(animated.image), path + ": built " + o.accel.kind);
    WorkloadPlan plan = plan_workload(scene, o.workload);
    if (!lights_added["added"].empty())
        for (Effect& e : plan.effects)
            if (e.name == "shadow") e.why += " (added by --lights " + o.lights + ")";
    if (accel_options.two_level) mark_instancing_simulated(plan, accel->image());
    std::string camera_source;
    Camera camera = choose_camera(o, scene, *accel, &camera_source);
    PinholeCamera pinhole = make_camera(camera, o.width, o.height);
    const std::string camera_where = path + ": camera from " + camera_source;
    check_camera(pinhole, camera_where);
    check_scene_reach(pinhole, scene.bounds, camera_where);

    TraceFolderWriter folder(o.out_dir, accel->image());
    const std::string scene_name = procedural ? o.scene : fs::path(path).stem().string();
    // The shading tables hold a record per *placed* triangle (44 bytes): an instanced scene too
    // large to flatten (the forest: hundreds of millions placed) would need tens of GiB, so its
    // trace is written without them, and says so (shading.enabled then refuses it by name).
    if (scene.triangle_count() <= kMaxShadedTriangles)
        folder.set_shading(scene, build_shading_scene(scene, scene_name, procedural, accel->image().end_address()));
    else
        scene.warnings.push_back("shading tables not written: the scene places " +
                                 std::to_string(scene.triangle_count()) + " triangles, more than the " +
                                 std::to_string(kMaxShadedTriangles) + " a trace's shading tables hold (44 bytes "
                                 "each); the frame (shading.enabled) cannot be replayed from this trace");
    uint32_t light_count = uint32_t(scene.lights.size() + (plan.emissive_prims.empty() ? 0 : 1));
    PreviewRender render(o.width, o.height, plan.wants(RayKind::shadow) ? light_count : 0);
    std::vector<uint64_t> first_ray, frame_rays;
    for (uint32_t f = 0; f < o.frames; ++f) {
        // Frame f: the instances posed, its TLAS bound, the same camera, its own seed.
        if (o.frames > 1) {
            pose_frame(scene, animated.motion, f);
            accel->bind_frame(f);
        }
        const std::string prefix = o.frames > 1 ? "frame " + std::to_string(f) + " " : "";
        SpawnContext ctx{&scene, &plan, o.bounces, frame_seed(o.seed, f), o.reflections == "glossy", o.roulette_after};
        first_ray.push_back(folder.rays_written());
        std::vector<PendingRay> wave = primary_rays(pinhole, o.width, o.height, camera_where);
        for (uint32_t depth = 0; !wave.empty(); ++depth) {
            std::string stage = prefix + (depth == 0 ? "primary" : "depth " + std::to_string(depth));
            WavefrontResult res =
                trace_wavefront(*accel, wave, o.threads, [&](uint64_t done) { report(done, wave.size(), stage); }, walk);
            folder.add_wavefront(plan, wave, res);
            if (f == 0) render.add(scene, wave, res.hits);  // the preview shows frame 0
            wave = next_wavefront(ctx, wave, res.hits);
        }
        frame_rays.push_back(folder.rays_written() - first_ray.back());
        if (o.frames > 1) folder.add_frame(first_ray.back());
    }

    json requested = "scene";  // the default: every kind the scene calls for
    if (!o.workload.empty()) {
        requested = json::array();
        for (RayKind k : o.workload) requested.push_back(ray_kind_name(k));
    }
    json extra = {
        {"camera", camera_json(camera, camera_source)},
        {"workload",
         {{"requested", requested},
          {"resolution", {o.width, o.height}},
          {"bounces", o.bounces},
          {"reflections", o.reflections},
          {"roulette_after", o.roulette_after},
          {"anyhit_order", o.anyhit_order},
          {"seed", o.seed},
          {"effects", effects_json(plan)},
          {"lights_added", lights_added}}},
        {"files", {{"render", "render.png"}}},
    };
    if (o.frames > 1) {
        pose_frame(scene, animated.motion, 0);  // the manifest describes frame 0
        extra["frames"] = frames_json(accel->image(), animated.timing, first_ray, frame_rays, scene, policy);
    }
    SceneLabel label{procedural ? o.scene : fs::path(path).stem().string(), procedural};
    render.write_png((fs::path(o.out_dir) / "render.png").string());
    return folder.finish(scene, label, accel->image(), load_ms, t_start, std::move(extra));
}

}  // namespace rtsim
