// Tracing bindings: trace_rays (numpy rays through the reference traversal), trace_scene (the
// whole tracer, with a progress callback) and the trace file reader (sections, verification).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
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
#include "traces/format/trace_checks.h"
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
        throw ArgumentError("camera: expected (eye, target, fov_degrees), got " +
                              std::to_string(seq.size()) + " items");
    }
    auto eye = seq[0].cast<std::vector<float>>();
    auto target = seq[1].cast<std::vector<float>>();
    if (eye.size() != 3 || target.size() != 3) {
        throw ArgumentError("camera: eye and target must have 3 coordinates each");
    }
    CameraOverride cam;
    cam.eye = Vec3(eye[0], eye[1], eye[2]);
    cam.target = Vec3(target[0], target[1], target[2]);
    cam.yfov_degrees = seq[2].cast<float>();
    if (!(cam.yfov_degrees > 0.0f && cam.yfov_degrees < 180.0f)) {
        throw ArgumentError("camera: field of view must be in (0, 180) degrees, got " +
                              std::to_string(cam.yfov_degrees));
    }
    return cam;
}

/// Builder settings {name: value} (None: none) as the C++ side takes them (AccelOptions::settings).
nlohmann::json settings_from(const py::object& settings) {
    if (settings.is_none()) return nlohmann::json::object();
    if (!py::isinstance<py::dict>(settings)) throw ArgumentError("build_settings: expected a dict of name: value");
    // Value by value, not through JSON text: a NaN or an infinity reaches the builder's range
    // check (which names the setting and its range), as a --build-set value does.
    nlohmann::json out = nlohmann::json::object();
    for (const auto& [key, value] : settings.cast<py::dict>()) {
        if (!py::isinstance<py::str>(key)) throw ArgumentError("build_settings: setting names must be text");
        const std::string name = key.cast<std::string>();
        if (py::isinstance<py::bool_>(value)) out[name] = value.cast<bool>();
        else if (py::isinstance<py::int_>(value)) {
            const py::int_ i = value.cast<py::int_>();
            const bool fits = py::int_(INT64_MIN) <= i && i <= py::int_(INT64_MAX);
            if (fits) out[name] = value.cast<int64_t>();
            else out[name] = value.cast<double>();  // out of every range: the builder says so
        }
        else if (py::isinstance<py::float_>(value)) out[name] = value.cast<double>();
        else if (py::isinstance<py::str>(value)) out[name] = value.cast<std::string>();
        else throw ArgumentError("build_settings: '" + name + "' must be a number, a bool or text");
    }
    return out;
}

/// A JSON value as the Python object json.loads makes of it.
py::object to_python(const nlohmann::json& j) { return py::module_::import("json").attr("loads")(j.dump()); }

/// The scene argument of trace_scene: a path, a procedural name, or a Scene (its source).
std::string scene_name(const py::object& obj) {
    if (py::isinstance<PyScene>(obj)) return obj.cast<PyScene&>().scene().source;
    return obj.cast<fs::path>().string();
}

/// Reads TraceOptions' defaults into a dict (TraceOptions::visit).
struct DefaultsReader {
    py::dict out;
    void operator()(const char* name, const std::vector<RayKind>&, const char*) { out[name] = py::none(); }
    void operator()(const char* name, const std::optional<CameraOverride>&, const char*) { out[name] = py::none(); }
    void operator()(const char* name, const nlohmann::json&, const char*) { out[name] = py::none(); }
    template <class T>
    void operator()(const char* name, const T& value, const char*) { out[name] = value; }
};

/// Applies keyword arguments to TraceOptions by name (TraceOptions::visit); None keeps the default.
struct KwargsApplier {
    const py::kwargs& kw;
    int used = 0;
    bool take(const char* name, py::object* value) {
        if (!kw.contains(name)) return false;
        ++used;
        *value = kw[name];
        return !value->is_none();
    }
    void operator()(const char* name, std::vector<RayKind>& kinds, const char*) {
        py::object v;
        if (!take(name, &v)) return;
        const auto names = v.cast<std::vector<std::string>>();
        if (names.empty()) throw ArgumentError("workload: empty list (None: what the scene calls for)");
        for (const std::string& kind : names) kinds.push_back(parse_ray_kind(kind.c_str()));
    }
    void operator()(const char* name, std::optional<CameraOverride>& camera, const char*) {
        py::object v;
        if (take(name, &v)) camera = camera_from(v);
    }
    void operator()(const char* name, nlohmann::json& settings, const char*) {
        py::object v;
        if (take(name, &v)) settings = settings_from(v);
    }
    template <class T>
    void operator()(const char* name, T& value, const char*) {
        py::object v;
        if (take(name, &v)) value = v.cast<T>();
    }
};

py::object trace_scene_py(const py::object& scene, const fs::path& out_dir, const py::object& progress,
                          const py::kwargs& options) {
    TraceOptions opt;
    KwargsApplier apply{options};
    opt.visit(apply);
    if (apply.used != int(options.size())) {
        DefaultsReader known;
        opt.visit(known);
        for (const auto& item : options)
            if (!known.out.contains(item.first))
                throw py::type_error("trace_scene: unknown option '" + item.first.cast<std::string>() +
                                     "' (options: " + py::str(py::list(known.out.attr("keys")())).cast<std::string>() + ")");
    }
    if (opt.width == 0 || opt.height == 0) throw ArgumentError("width and height must be positive");
    opt.scene = scene_name(scene);
    opt.out_dir = out_dir.string();
    opt.procedural.seed = opt.seed;
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
                          const std::string& accel, const std::string& builder, const py::object& build_settings) {
    const std::vector<Ray> rays = rays_from_arrays(origins, directions, tmin, tmax);
    const auto n = static_cast<py::ssize_t>(rays.size());
    if (kinds.ndim() != 1 || kinds.shape(0) != n)
        throw ArgumentError("kind: expected one ray kind per ray (" + std::to_string(n) + ")");
    if (any_hit.ndim() != 1 || any_hit.shape(0) != n)
        throw ArgumentError("any_hit: expected one flag per ray (" + std::to_string(n) + ")");
    std::vector<PendingRay> pending(rays.size());
    for (size_t i = 0; i < rays.size(); ++i) {
        const uint8_t kind = kinds.data()[i];
        if (kind >= kRayKindCount)
            throw ArgumentError("kind: ray " + std::to_string(i) + " has kind " + std::to_string(kind) +
                                  " (0..4: primary, shadow, reflection, diffuse, refraction)");
        pending[i].ray = rays[i];
        pending[i].kind = RayKind(kind);
        pending[i].pixel = uint32_t(i);
        pending[i].any_hit = any_hit.data()[i];
    }
    AccelOptions accel_options;
    accel_options.kind = accel;
    accel_options.builder = builder;
    accel_options.settings = settings_from(build_settings);
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
        // And what rtsim-sim checks of the records: one HITS and WORK record per ray, a frame
        // table that covers the rays (trace_checks.h). Payload CRCs: verify_trace, per section.
        check_ray_sections(reader);
        const uint32_t frames =
            reader.has(SectionKind::accel) ? load_accel(read_accel_image(reader), reader.path())->frame_count() : 1;
        read_frame_table(reader, frames);
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
    // WorkCounts as a numpy record: its fields as work_counts.h declares them (trace_rays' `work`
    // field, and the trace's WORK section through work_fields()).
    ::pybind11::detail::npy_format_descriptor<WorkCounts>::register_dtype({
#define RTSIM_WORK_DESCRIPTOR(name, tests_of, plan_step, doc) PYBIND11_FIELD_DESCRIPTOR(WorkCounts, name),
        RTSIM_WORK_FIELDS(RTSIM_WORK_DESCRIPTOR)
#undef RTSIM_WORK_DESCRIPTOR
    });
    m.def(
        "work_fields",
        [] {
            py::list out;
            for (const WorkFieldInfo& f : kWorkFields)
                out.append(py::dict(py::arg("name") = f.name, py::arg("doc") = f.doc, py::arg("traced") = f.traced,
                                    py::arg("tests_of") = f.tests_of == kNoOpKind ? py::object(py::none())
                                                                                  : py::str(op_kind_name(f.tests_of))));
            return out;
        },
        "The per-ray work counters in WORK record order (traces/common/work_counts.h): name, doc and the\n"
        "operation kind whose tests each counts (None for none).");
    PYBIND11_NUMPY_DTYPE(PyHit, prim, inst, t, u, v, valid, work);
    m.def(
        "section_layouts",
        [] {
            const nlohmann::json j = {{"rays", layout_json(layout_of(static_cast<const RayRecord*>(nullptr)))},
                                      {"hits", layout_json(layout_of(static_cast<const HitRecord*>(nullptr)))},
                                      {"work", layout_json(layout_of(static_cast<const WorkRecord*>(nullptr)))},
                                      {"frms", layout_json(layout_of(static_cast<const FrameRecord*>(nullptr)))},
                                      {"matl", layout_json(layout_of(static_cast<const MaterialRecord*>(nullptr)))},
                                      {"texr", layout_json(layout_of(static_cast<const TextureRecord*>(nullptr)))},
                                      {"ptri", layout_json(layout_of(static_cast<const TriShadeRecord*>(nullptr)))},
                                      {"shad", layout_json(layout_of(static_cast<const ShadeRecord*>(nullptr)))},
                                      {"txft", layout_json(scalar_layout<uint64_t>())}};
            return py::module_::import("json").attr("loads")(j.dump());
        },
        "The record layouts of the trace's RAYS, HITS, WORK, FRMS and shading sections (MATL, TEXR, PTRI,\n"
        "SHAD, TXFT) as C++ declares them\n"
        "(traces/format/trace_format.h): {section: [{name, type, offset, shape}]}. Image regions carry\n"
        "their layouts in the ACCL descriptor.");

    m.def("trace_rays", &trace_rays, py::arg("scene"), py::arg("origins"), py::arg("directions"),
          py::arg("tmin") = 0.0f, py::arg("tmax") = std::numeric_limits<float>::infinity(),
          py::arg("any_hit") = false,
          "Traces rays (origins and directions: (N, 3)) through the scene's reference BVH.\n"
          "Returns a structured array with fields prim (-1: miss), inst, t, u, v, valid\n"
          "(False for rays rejected as invalid: NaN, zero direction, tmin > tmax) and work,\n"
          "the traversal's work counts (work.dtype.names: the C++ WorkCounts fields).");
    m.def("trace_scene", &trace_scene_py, py::arg("scene"), py::arg("out_dir"), py::kw_only(),
          py::arg("progress") = py::none(),
          "Runs the reference tracer: writes OUT/trace.rtt, manifest.json and render.png and\n"
          "returns the manifest. Keyword options are trace_defaults()'s (None or absent: the\n"
          "default): workload (ray kinds; None: every kind the scene calls for), width, height,\n"
          "bounces, seed, camera, accel and builder (accel_kinds()), build_settings ({name: value}\n"
          "over the builder's settings: accel_kinds()[i]['settings'][builder]), flatten,\n"
          "hairball_triangles, threads, frames. progress(done, total, stage) is called now and then.");
    m.def(
        "trace_defaults",
        [] {
            TraceOptions opt;
            DefaultsReader r;
            opt.visit(r);
            return r.out;
        },
        "The tracer's option defaults (traces/tracer/tracer.h, TraceOptions), declared once in C++.");
    m.def("write_trace", &write_trace_py, py::arg("scene"), py::arg("origins"),
          py::arg("directions"), py::arg("tmin"), py::arg("tmax"), py::arg("kinds"),
          py::arg("any_hit"), py::arg("out_dir"), py::arg("threads") = 0u,
          py::arg("progress") = py::none(), py::arg("accel") = AccelOptions{}.kind,
          py::arg("builder") = AccelOptions{}.builder, py::arg("build_settings") = py::none(),
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
                py::dict settings;
                for (const std::string& b : k.builders) settings[py::str(b)] = to_python(accel_settings_schema(k.name, b));
                d["settings"] = settings;
                out.append(d);
            }
            return out;
        },
        "The acceleration structures this build knows: name, description, builders, and per builder\n"
        "its settings {name: {type, default, unit, min, max, doc}} (docs/accel.md, Builder settings).");
    m.def(
        "structure_alternatives",
        [](const std::string& kind, bool compressed_leaves, bool curved) {
            py::list out;
            for (const StructureAlternative& a : structure_alternatives(kind, compressed_leaves, curved))
                out.append(py::make_tuple(a.key, a.value, structure_alternative_dir(a)));
            return out;
        },
        py::arg("kind"), py::arg("compressed_leaves") = false, py::arg("curved") = false,
        "The structures one step from a trace's, as (key, value, folder): ('accel', KIND) or\n"
        "('compressed_leaves', 'true'), and where rtsim trace --alternatives writes it beside the\n"
        "trace ('alternatives/KEY=VALUE'); what the verdict weighs.");
    m.attr("trace_version") = kTraceVersion;  // the trace format this build writes and reads
    m.def("trace_sections", &trace_sections, py::arg("path"),
          "Validates a trace file's header, section table and BVH image; returns its sections.");
    m.def(
        "verify_trace",
        [](const fs::path& path, const std::optional<std::string>& section) {
            py::gil_scoped_release release;
            TraceReader reader(path.string());
            if (!section) return reader.verify_all();
            for (const SectionInfo& s : reader.sections())
                if (section_name(s.kind) == *section) return reader.verify_section(s.kind);
            throw Error(path.string() + ": no section " + *section + " in this trace");
        },
        py::arg("path"), py::arg("section") = py::none(),
        "Checks every chunk's CRC32 (of one section, named as trace_sections names it, if given);\n"
        "raises RtsimError naming the section and the first bad chunk.");
}

}  // namespace rtsim::py_bind
