// Tracing bindings: trace_rays (numpy rays through the reference traversal), trace_scene (the
// whole tracer, with a progress callback) and the trace file reader (sections, verification).
#include <chrono>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "python/src/bindings.h"
#include "traces/bvh/bvh_image_checks.h"
#include "traces/common/error.h"
#include "traces/format/trace_reader.h"
#include "traces/isect/traversal.h"
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
};

using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

/// (N, 3) float array or a ValueError naming the argument.
FloatArray as_vectors(const py::handle& obj, const char* name) {
    FloatArray a = FloatArray::ensure(obj);
    if (!a) throw py::value_error(std::string(name) + ": expected an array of floats");
    if (a.ndim() != 2 || a.shape(1) != 3) {
        std::string shape = "(";
        for (py::ssize_t i = 0; i < a.ndim(); ++i) shape += (i ? ", " : "") + std::to_string(a.shape(i));
        throw py::value_error(std::string(name) + ": expected shape (N, 3), got " + shape +
                              (a.ndim() == 1 ? ",)" : ")"));
    }
    return a;
}

/// A scalar (broadcast) or an (N,) array; returns the values and the stride (0 or 1).
std::pair<FloatArray, py::ssize_t> as_limits(const py::handle& obj, py::ssize_t n, const char* name) {
    FloatArray a = FloatArray::ensure(obj);
    if (!a) throw py::value_error(std::string(name) + ": expected a float or an array of floats");
    if (a.ndim() == 0) return {a, 0};
    if (a.ndim() == 1 && a.shape(0) == n) return {a, 1};
    if (a.ndim() == 1 && a.shape(0) == 1) return {a, 0};
    throw py::value_error(std::string(name) + ": expected a scalar or shape (" + std::to_string(n) +
                          ",), got an array with " + std::to_string(a.ndim()) + " dimensions and " +
                          std::to_string(a.size()) + " elements");
}

py::array trace_rays(PyScene& scene, const py::object& origins, const py::object& directions,
                     const py::object& tmin, const py::object& tmax, bool any_hit) {
    FloatArray o = as_vectors(origins, "origins");
    FloatArray d = as_vectors(directions, "directions");
    const py::ssize_t n = o.shape(0);
    if (d.shape(0) != n) {
        throw py::value_error("directions: expected " + std::to_string(n) +
                              " rays (as many as origins), got " + std::to_string(d.shape(0)));
    }
    auto [lo, lo_step] = as_limits(tmin, n, "tmin");
    auto [hi, hi_step] = as_limits(tmax, n, "tmax");

    const HwBvh& bvh = scene.bvh();  // builds with the GIL held on entry
    py::array_t<PyHit> out(n);
    PyHit* hits = out.mutable_data();
    const float* po = o.data();
    const float* pd = d.data();
    const float* plo = lo.data();
    const float* phi = hi.data();
    const TraversalMode mode = any_hit ? TraversalMode::any_hit : TraversalMode::closest_hit;
    {
        py::gil_scoped_release release;
        for (py::ssize_t i = 0; i < n; ++i) {
            Ray ray;
            ray.origin = Vec3(po[3 * i], po[3 * i + 1], po[3 * i + 2]);
            ray.direction = Vec3(pd[3 * i], pd[3 * i + 1], pd[3 * i + 2]);
            ray.tmin = plo[i * lo_step];
            ray.tmax = phi[i * hi_step];
            const bool valid = ray_is_valid(ray);
            const Hit h = valid ? trace_ray(bvh, ray, mode) : Hit{};
            hits[i] = PyHit{h.prim, h.inst, h.t, h.u, h.v, valid};
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
                          const std::vector<std::string>& workload, uint32_t width,
                          uint32_t height, uint32_t bounces, uint64_t seed,
                          const py::object& camera, unsigned threads, uint32_t hairball_triangles,
                          const py::object& progress) {
    TraceOptions opt;
    opt.scene = scene_name(scene);
    opt.out_dir = out_dir.string();
    opt.workload.clear();
    for (const std::string& kind : workload) opt.workload.push_back(parse_ray_kind(kind.c_str()));
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

py::list trace_sections(const fs::path& path) {
    std::vector<SectionInfo> sections;
    {
        py::gil_scoped_release release;
        TraceReader reader(path.string());
        sections = reader.sections();
        // The BVH image must be a tree the traversal can walk, not just bytes with valid CRCs.
        if (reader.has(SectionKind::bvh_nodes) || reader.has(SectionKind::triangles))
            validate_bvh_image(reader.read_all<HwNode>(SectionKind::bvh_nodes),
                               reader.read_all<HwTriangle>(SectionKind::triangles), reader.path());
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
    PYBIND11_NUMPY_DTYPE(PyHit, prim, inst, t, u, v, valid);

    m.def("trace_rays", &trace_rays, py::arg("scene"), py::arg("origins"), py::arg("directions"),
          py::arg("tmin") = 0.0f, py::arg("tmax") = std::numeric_limits<float>::infinity(),
          py::arg("any_hit") = false,
          "Traces rays (origins and directions: (N, 3)) through the scene's reference BVH.\n"
          "Returns a structured array with fields prim (-1: miss), inst, t, u, v and valid\n"
          "(False for rays rejected as invalid: NaN, zero direction, tmin > tmax).");
    m.def("trace_scene", &trace_scene_py, py::arg("scene"), py::arg("out_dir"),
          py::arg("workload") = std::vector<std::string>{"primary"}, py::arg("width") = 320u,
          py::arg("height") = 240u, py::arg("bounces") = 1u, py::arg("seed") = 1u,
          py::arg("camera") = py::none(), py::arg("threads") = 0u,
          py::arg("hairball_triangles") = 200000u, py::arg("progress") = py::none(),
          "Runs the reference tracer: writes OUT/trace.rtt, manifest.json and render.png and\n"
          "returns the manifest. progress(done, total, stage) is called now and then.");
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
