// Tracing bindings: trace_rays (numpy rays through the reference traversal), trace_scene (the
// whole tracer, with a progress callback) and the trace file reader (sections, verification).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "python/src/bindings.h"
#include "python/src/ray_args.h"
#include "traces/accel/accel.h"
#include "traces/accel/accel_io.h"
#include "traces/accel/bvh2/bvh2.h"
#include "traces/common/error.h"
#include "traces/format/trace_reader.h"
#include "traces/scene/procedural.h"
#include "traces/tracer/ray_trace.h"
#include "traces/tracer/tracer.h"

namespace py = pybind11;
namespace fs = std::filesystem;

namespace rtsim::py_bind {
namespace {

/// One element of trace_rays' result (numpy structured dtype).
struct PyHit {
    int32_t prim;
    int32_t inst;
    float t;
    float u;
    float v;
    bool valid;  ///< false: the ray was rejected as invalid (NaN, zero direction, tmin > tmax)
    WorkCounts work;  ///< the reference traversal's work (numpy fields: bind_trace below)
};

py::array trace_rays(PyScene& scene, const py::object& origins, const py::object& directions,
                     const py::object& tmin, const py::object& tmax, bool any_hit) {
    const std::vector<Ray> rays = rays_from_arrays(origins, directions, tmin, tmax);
    const HwBvh& bvh = scene.bvh();  // builds with the GIL held on entry
    py::array_t<PyHit> out(static_cast<py::ssize_t>(rays.size()));
    PyHit* hits = out.mutable_data();
    const TraversalMode mode = any_hit ? TraversalMode::any_hit : TraversalMode::closest_hit;
    {
        py::gil_scoped_release release;
        for (size_t i = 0; i < rays.size(); ++i) {
            const bool valid = ray_is_valid(rays[i]);
            WorkCounts work;
            const Hit h = valid ? trace_ray(bvh, rays[i], mode, &work) : Hit{};
            hits[i] = PyHit{h.prim, h.inst, h.t, h.u, h.v, valid, work};
        }
    }
    return std::move(out);
}

/// Calls a Python progress callable from C++ at most every 50 ms (and at every stage change),
/// with the GIL re-acquired; a pending Ctrl-C or an exception in the callable aborts the trace.
ProgressFn make_progress(const py::object& callback) {
    if (callback.is_none()) {
        // Still let Ctrl-C through while the tracer runs.
        return [](uint64_t, uint64_t, const std::string&) {
            py::gil_scoped_acquire gil;
            if (PyErr_CheckSignals() != 0) throw py::error_already_set();
        };
    }
    struct State {
        std::string stage;
        std::chrono::steady_clock::time_point last{};
    };
    auto state = std::make_shared<State>();
    return [callback, state](uint64_t done, uint64_t total, const std::string& stage) {
        const auto now = std::chrono::steady_clock::now();
        const bool due = stage != state->stage || done >= total ||
                         now - state->last > std::chrono::milliseconds(50);
        if (!due) return;
        state->stage = stage;
        state->last = now;
        py::gil_scoped_acquire gil;
        if (PyErr_CheckSignals() != 0) throw py::error_already_set();
        callback(done, total, stage);
    };
}

std::optional<CameraOverride> camera_from(const py::object& obj) {
    if (obj.is_none()) return std::nullopt;
    auto seq = obj.cast<py::sequence>();
    if (seq.size() != 3) {
        throw py::value_error("camera: expected (eye, target, fov_degrees), got " +
                              std::to_string(seq.size()) + " items");
    }
    auto eye = seq[0].cast<std::vector<float>>();
    auto target = seq[1].cast<std::vector<float>>();
    if (eye.size() != 3 || target.size() != 3) {
        throw py::value_error("camera: eye and target must have 3 coordinates each");
    }
    CameraOverride cam;
    cam.eye = Vec3(eye[0], eye[1], eye[2]);
    cam.target = Vec3(target[0], target[1], target[2]);
    cam.yfov_degrees = seq[2].cast<float>();
    if (!(cam.yfov_degrees > 0.0f && cam.yfov_degrees < 180.0f)) {
        throw py::value_error("camera: field of view must be in (0, 180) degrees, got " +
                              std::to_string(cam.yfov_degrees));
    }
    return cam;
}

/// The scene argument of trace_scene: a path, a procedural name, or a Scene (its source).
std::string scene_name(const py::object& obj) {
    if (py::isinstance<PyScene>(obj)) return obj.cast<PyScene&>().scene().source;
    return obj.cast<fs::path>().string();
}

py::object trace_scene_py(const py::object& scene, const fs::path& out_dir,
                          const std::optional<std::vector<std::string>>& workload, uint32_t width,
                          uint32_t height, uint32_t bounces, uint64_t seed,
                          const py::object& camera, unsigned threads, uint32_t hairball_triangles,
                          const py::object& progress, const std::string& accel, const std::string& builder,
                          bool flatten, uint32_t frames) {
    TraceOptions opt;
    opt.accel.kind = accel;
    opt.accel.builder = builder;
    opt.flatten = flatten;
    opt.frames = frames;
    opt.scene = scene_name(scene);
    opt.out_dir = out_dir.string();
    if (workload) {  // None: every kind the scene calls for
        if (workload->empty()) throw py::value_error("workload: empty list (None: what the scene calls for)");
        for (const std::string& kind : *workload) opt.workload.push_back(parse_ray_kind(kind.c_str()));
    }
    if (width == 0 || height == 0) throw py::value_error("width and height must be positive");
    opt.width = width;
    opt.height = height;
    opt.bounces = bounces;
    opt.seed = seed;
    opt.camera = camera_from(camera);
    opt.threads = threads;
    opt.procedural.hairball_triangles = hairball_triangles;
    opt.procedural.seed = seed;
    const ProgressFn fn = make_progress(progress);

    std::string manifest;
    {
        py::gil_scoped_release release;
        manifest = trace_scene(opt, fn).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    }
    return py::module_::import("json").attr("loads")(manifest);
}

/// How a Scene is named in a manifest: a procedural scene by its name, a file by its stem.
SceneLabel label_of(const Scene& scene) {
    const bool procedural = !fs::is_regular_file(scene.source) && is_procedural_scene(scene.source);
    return {procedural ? scene.source : fs::path(scene.source).stem().string(), procedural};
}

/// write_trace: user rays (one kind and any-hit flag per ray) traced and written as a trace.
py::object write_trace_py(PyScene& scene, const py::object& origins, const py::object& directions,
                          const py::object& tmin, const py::object& tmax,
                          const py::array_t<uint8_t, py::array::c_style | py::array::forcecast>& kinds,
                          const py::array_t<bool, py::array::c_style | py::array::forcecast>& any_hit,
                          const fs::path& out_dir, unsigned threads, const py::object& progress,
                          const std::string& accel, const std::string& builder) {
    const std::vector<Ray> rays = rays_from_arrays(origins, directions, tmin, tmax);
    const auto n = static_cast<py::ssize_t>(rays.size());
    if (kinds.ndim() != 1 || kinds.shape(0) != n)
        throw py::value_error("kind: expected one ray kind per ray (" + std::to_string(n) + ")");
    if (any_hit.ndim() != 1 || any_hit.shape(0) != n)
        throw py::value_error("any_hit: expected one flag per ray (" + std::to_string(n) + ")");
    std::vector<PendingRay> pending(rays.size());
    for (size_t i = 0; i < rays.size(); ++i) {
        const uint8_t kind = kinds.data()[i];
        if (kind >= kRayKindCount)
            throw py::value_error("kind: ray " + std::to_string(i) + " has kind " + std::to_string(kind) +
                                  " (0..4: primary, shadow, reflection, diffuse, refraction)");
        pending[i].ray = rays[i];
        pending[i].kind = RayKind(kind);
        pending[i].pixel = uint32_t(i);
        pending[i].any_hit = any_hit.data()[i];
    }
    AccelOptions accel_options;
    accel_options.kind = accel;
    accel_options.builder = builder;
    accel_options.build_threads = threads ? threads : std::max(1u, std::thread::hardware_concurrency());
    validate_accel_options(accel_options);
    RayTraceOptions opt;
    opt.out_dir = out_dir.string();
    opt.threads = threads;
    const ProgressFn fn = make_progress(progress);
    const SceneLabel label = label_of(scene.scene());
    std::string manifest;
    {
        // The structure is built exactly as trace_scene builds it (traces/accel/accel.h).
        py::gil_scoped_release release;
        const std::unique_ptr<Accel> built =
            load_accel(build_accel(scene.scene(), accel_options), label.name + ": built " + accel);
        manifest = write_ray_trace(scene.scene(), label, *built, pending, opt, fn)
                       .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    }
    return py::module_::import("json").attr("loads")(manifest);
}

py::list trace_sections(const fs::path& path) {
    std::vector<SectionInfo> sections;
    {
        py::gil_scoped_release release;
        TraceReader reader(path.string());
        sections = reader.sections();
        // The structure's image must be one its traversal can walk, not just bytes with valid
        // CRCs: load_accel validates it structurally (docs/accel.md).
        if (reader.has(SectionKind::accel)) load_accel(read_accel_image(reader), reader.path());
    }
    py::list out;
    for (const SectionInfo& s : sections) {
        py::dict d;
        d["kind"] = section_name(s.kind);
        d["fourcc"] = static_cast<uint32_t>(s.kind);
        d["record_bytes"] = s.record_bytes;
        d["record_count"] = s.record_count;
        d["offset"] = s.offset;
        d["bytes"] = s.bytes;
        d["chunk_bytes"] = s.chunk_bytes;
        d["crc_offset"] = s.crc_offset;
        out.append(d);
    }
    return out;
}

}  // namespace

void bind_trace(py::module_& m) {
    // The one mapping of the C++ WorkCounts fields to Python names (trace_rays' `work` field).
    PYBIND11_NUMPY_DTYPE(WorkCounts, steps, box_tests, tri_tests, anyhit_calls, transforms,
                         cell_steps, plane_tests, refs);
    PYBIND11_NUMPY_DTYPE(PyHit, prim, inst, t, u, v, valid, work);

    m.def("trace_rays", &trace_rays, py::arg("scene"), py::arg("origins"), py::arg("directions"),
          py::arg("tmin") = 0.0f, py::arg("tmax") = std::numeric_limits<float>::infinity(),
          py::arg("any_hit") = false,
          "Traces rays (origins and directions: (N, 3)) through the scene's reference BVH.\n"
          "Returns a structured array with fields prim (-1: miss), inst, t, u, v, valid\n"
          "(False for rays rejected as invalid: NaN, zero direction, tmin > tmax) and work,\n"
          "the traversal's work counts (work.dtype.names: the C++ WorkCounts fields).");
    m.def("trace_scene", &trace_scene_py, py::arg("scene"), py::arg("out_dir"),
          py::arg("workload") = py::none(), py::arg("width") = 320u,
          py::arg("height") = 240u, py::arg("bounces") = 1u, py::arg("seed") = 1u,
          py::arg("camera") = py::none(), py::arg("threads") = 0u,
          py::arg("hairball_triangles") = 200000u, py::arg("progress") = py::none(),
          py::arg("accel") = "bvh2", py::arg("builder") = "", py::arg("flatten") = false,
          py::arg("frames") = 1u,
          "Runs the reference tracer: writes OUT/trace.rtt, manifest.json and render.png and\n"
          "returns the manifest. workload: ray kinds (None: every kind the scene calls for).\n"
          "progress(done, total, stage) is called now and then. accel and builder choose the\n"
          "acceleration structure (accel_kinds()); instanced scenes get a BLAS of that kind per\n"
          "mesh and a TLAS over the instances unless flatten is true. frames > 1 animates the\n"
          "instances (docs/accel.md, Frames): BLASes once, a TLAS and the workload per frame.");
    m.def("write_trace", &write_trace_py, py::arg("scene"), py::arg("origins"),
          py::arg("directions"), py::arg("tmin"), py::arg("tmax"), py::arg("kinds"),
          py::arg("any_hit"), py::arg("out_dir"), py::arg("threads") = 0u,
          py::arg("progress") = py::none(), py::arg("accel") = "bvh2",
          py::arg("builder") = "binned",
          "Traces the given rays (kinds: RayKind per ray, any_hit: flag per ray) and writes\n"
          "OUT/trace.rtt and manifest.json exactly as trace_scene writes a workload; returns\n"
          "the manifest. Use rtsim.write_trace, which takes kind names and scene names.");
    m.def(
        "accel_kinds",
        [] {
            py::list out;
            for (const AccelKindInfo& k : accel_kinds()) {
                py::dict d;
                d["name"] = k.name;
                d["description"] = k.description;
                d["builders"] = k.builders;
                out.append(d);
            }
            return out;
        },
        "The acceleration structures this build knows: name, description, builders.");
    m.attr("trace_version") = kTraceVersion;  // the trace format this build writes and reads
    m.def("trace_sections", &trace_sections, py::arg("path"),
          "Validates a trace file's header, section table and BVH image; returns its sections.");
    m.def(
        "verify_trace",
        [](const fs::path& path) {
            py::gil_scoped_release release;
            TraceReader reader(path.string());
            reader.verify_all();
        },
        py::arg("path"), "Checks every chunk's CRC32; raises RtsimError naming the first bad one.");
}

}  // namespace rtsim::py_bind
