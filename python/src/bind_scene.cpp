// Scene bindings: load_scene (glTF path or procedural name), the Scene object with its
// triangles as a zero-copy numpy view, and the procedural scene writers.
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "python/src/bindings.h"
#include "traces/bvh/builder.h"
#include "traces/common/error.h"
#include "traces/common/files.h"
#include "traces/scene/gltf_loader.h"
#include "traces/scene/procedural.h"

namespace py = pybind11;
namespace fs = std::filesystem;

namespace rtsim::py_bind {

const HwBvh& PyScene::bvh() {
    if (!m_bvh) {
        // Built with the GIL released: a large scene takes seconds. Other threads calling
        // bvh() meanwhile are serialised by a mutex below.
        static std::mutex build_mutex;
        py::gil_scoped_release release;
        std::lock_guard<std::mutex> lock(build_mutex);
        if (!m_bvh) m_bvh = std::make_unique<HwBvh>(build_bvh(m_scene));
    }
    return *m_bvh;
}

namespace {

static_assert(sizeof(Triangle) == 9 * sizeof(float), "Triangle must be 9 packed floats");

py::tuple vec3(const Vec3& v) { return py::make_tuple(v.x, v.y, v.z); }

const char* alpha_mode_name(AlphaMode mode) {
    switch (mode) {
        case AlphaMode::opaque: return "OPAQUE";
        case AlphaMode::mask: return "MASK";
        case AlphaMode::blend: return "BLEND";
    }
    return "OPAQUE";
}

const char* light_type_name(LightType type) {
    switch (type) {
        case LightType::point: return "point";
        case LightType::spot: return "spot";
        case LightType::directional: return "directional";
    }
    return "point";
}

py::list materials_of(const Scene& s) {
    py::list out;
    for (const Material& m : s.materials) {
        py::dict d;
        d["name"] = m.name;
        d["base_color"] = py::make_tuple(m.base_color.x, m.base_color.y, m.base_color.z,
                                         m.base_color.w);
        d["metallic"] = m.metallic;
        d["roughness"] = m.roughness;
        d["alpha_mode"] = alpha_mode_name(m.alpha_mode);
        d["alpha_cutoff"] = m.alpha_cutoff;
        d["alpha_coverage"] = m.alpha_coverage;
        d["transmission"] = m.transmission;
        d["ior"] = m.ior;
        d["emissive"] = vec3(m.emissive);
        out.append(d);
    }
    return out;
}

py::list lights_of(const Scene& s) {
    py::list out;
    for (const Light& l : s.lights) {
        py::dict d;
        d["name"] = l.name;
        d["type"] = light_type_name(l.type);
        d["position"] = vec3(l.position);
        d["direction"] = vec3(l.direction);
        d["color"] = vec3(l.color);
        d["intensity"] = l.intensity;
        d["range"] = l.range;
        d["inner_cone"] = l.inner_cone;
        d["outer_cone"] = l.outer_cone;
        out.append(d);
    }
    return out;
}

py::list cameras_of(const Scene& s) {
    py::list out;
    for (const Camera& c : s.cameras) {
        py::dict d;
        d["name"] = c.name;
        d["eye"] = vec3(c.eye);
        d["forward"] = vec3(c.forward);
        d["up"] = vec3(c.up);
        d["yfov"] = c.yfov;
        d["aspect"] = c.aspect;
        out.append(d);
    }
    return out;
}

py::dict bvh_stats_of(PyScene& ps) {
    const BvhStats& st = ps.bvh().stats;
    py::dict d;
    d["nodes"] = st.nodes;
    d["leaves"] = st.leaves;
    d["max_depth"] = st.max_depth;
    d["avg_leaf_size"] = st.avg_leaf_size;
    d["max_leaf_size"] = st.max_leaf_size;
    d["sah_cost"] = st.sah_cost;
    d["build_ms"] = st.build_ms;
    return d;
}

/// (N, 3, 3) float32 view of the world-space triangles; the array keeps the Scene alive.
py::array triangles_of(py::object self) {
    const Scene& s = self.cast<PyScene&>().scene();
    const auto n = static_cast<py::ssize_t>(s.triangles.size());
    const auto f = static_cast<py::ssize_t>(sizeof(float));
    const float* data = n ? &s.triangles[0].v0.x : nullptr;
    py::array_t<float> arr({n, py::ssize_t{3}, py::ssize_t{3}}, {9 * f, 3 * f, f}, data, self);
    arr.attr("setflags")(py::arg("write") = false);
    return std::move(arr);
}

/// Writes a procedural scene into a private temporary folder, loads it and removes the files.
Scene load_procedural(const std::string& name, uint32_t hairball_triangles, uint64_t seed) {
    ProceduralOptions opt;
    opt.hairball_triangles = hairball_triangles;
    opt.seed = seed;
    static std::atomic<unsigned> counter{0};
    fs::path dir = fs::temp_directory_path() /
                   ("rtsim-scene-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) +
                    "-" + name);
    Scene scene;
    try {
        fs::create_directories(dir);
        scene = load_gltf(write_procedural_scene(name, dir.string(), opt));
    } catch (...) {
        std::error_code ec;
        fs::remove_all(dir, ec);
        throw;
    }
    std::error_code ec;
    fs::remove_all(dir, ec);
    scene.source = name;
    return scene;
}

PyScene load_scene(const fs::path& path, uint32_t hairball_triangles, uint64_t seed) {
    const std::string text = path.string();
    py::gil_scoped_release release;
    if (!fs::is_regular_file(path) && is_procedural_scene(text)) {
        return PyScene(load_procedural(text, hairball_triangles, seed));
    }
    if (!fs::exists(path)) {
        std::string known;
        for (const std::string& n : procedural_scene_names()) known += (known.empty() ? "" : ", ") + n;
        for (const std::string& n : instanced_procedural_scene_names()) known += ", " + n;
        for (const std::string& n : sphere_procedural_scene_names()) known += ", " + n;
        throw Error(text + ": no such file, and not a built-in scene (" + known + ")");
    }
    return PyScene(load_gltf(text));
}

std::string repr_of(const PyScene& ps) {
    const Scene& s = ps.scene();
    return "<rtsim.Scene '" + s.source + "': " + std::to_string(s.triangles.size()) +
           " triangles, " + std::to_string(s.instances.size()) + " instances, " +
           std::to_string(s.materials.size()) + " materials, " + std::to_string(s.lights.size()) +
           " lights>";
}

}  // namespace

void bind_scene(py::module_& m) {
    py::class_<PyScene>(m, "Scene", "A loaded scene (read-only); see rtsim.load_scene.")
        .def("triangles", &triangles_of,
             "World-space vertices as a read-only float32 array (N, 3, 3), indexed by primitive id.")
        .def_property_readonly("triangle_count", [](const PyScene& s) { return s.scene().triangle_count(); })
        .def_property_readonly("instance_count", [](const PyScene& s) { return s.scene().instances.size(); })
        .def_property_readonly("mesh_count", [](const PyScene& s) { return s.scene().meshes.size(); })
        .def_property_readonly(
            "instances",
            [](const PyScene& s) {
                // Placements in scene order: hits' inst indexes this list, and a hit's primitive
                // is prim_base + its index in the mesh (docs/accel.md, "Two-level structures").
                py::list out;
                for (const Instance& inst : s.scene().instances) {
                    py::list rows;
                    for (int r = 0; r < 4; ++r)
                        rows.append(py::make_tuple(inst.object_to_world[0][r], inst.object_to_world[1][r],
                                                   inst.object_to_world[2][r], inst.object_to_world[3][r]));
                    py::dict d;
                    d["mesh"] = inst.mesh;
                    d["prim_base"] = inst.prim_base;
                    d["node"] = inst.node;
                    d["object_to_world"] = rows;
                    out.append(d);
                }
                return out;
            },
            "Instances in scene order: mesh, prim_base, glTF node and the 4x4 object_to_world "
            "matrix (rows, double).")
        .def_property_readonly("uses_instancing", [](const PyScene& s) { return s.scene().uses_instancing(); })
        .def_property_readonly("materials", [](const PyScene& s) { return materials_of(s.scene()); })
        .def_property_readonly("lights", [](const PyScene& s) { return lights_of(s.scene()); })
        .def_property_readonly("cameras", [](const PyScene& s) { return cameras_of(s.scene()); })
        .def_property_readonly("bounds", [](const PyScene& s) {
            return py::make_tuple(vec3(s.scene().bounds.lo), vec3(s.scene().bounds.hi));
        })
        .def_property_readonly("warnings", [](const PyScene& s) { return s.scene().warnings; })
        .def_property_readonly("source", [](const PyScene& s) { return s.scene().source; })
        .def_property_readonly("triangle_materials", [](py::object self) {
            const Scene& s = self.cast<PyScene&>().scene();
            py::array_t<uint32_t> arr({static_cast<py::ssize_t>(s.tri_material.size())},
                                      {static_cast<py::ssize_t>(sizeof(uint32_t))},
                                      s.tri_material.data(), self);
            arr.attr("setflags")(py::arg("write") = false);
            return arr;
        }, "Material index of each primitive (read-only uint32 array).")
        .def("bvh_stats", &bvh_stats_of, "Statistics of the hardware BVH (built on first use).")
        .def("__repr__", &repr_of);

    m.def("load_scene", &load_scene, py::arg("path"), py::arg("hairball_triangles") = 200000u,
          py::arg("seed") = 1u,
          "Loads a .gltf/.glb file, or a built-in procedural scene by name ('cornell', ...).");
    m.def(
        "procedural_scene_names",
        [] {
            std::vector<std::string> names = procedural_scene_names();
            for (const std::string& n : instanced_procedural_scene_names()) names.push_back(n);
            for (const std::string& n : sphere_procedural_scene_names()) names.push_back(n);
            return names;
        },
        "Names of the built-in scenes (the instanced forest and grove, then the sphere scenes, last).");
    m.def(
        "write_procedural_scene",
        [](const std::string& name, const fs::path& dir, uint32_t hairball_triangles, uint64_t seed) {
            ProceduralOptions opt;
            opt.hairball_triangles = hairball_triangles;
            opt.seed = seed;
            py::gil_scoped_release release;
            make_output_folder(dir.string(), "scene output");
            return write_procedural_scene(name, dir.string(), opt);
        },
        py::arg("name"), py::arg("dir"), py::arg("hairball_triangles") = 200000u,
        py::arg("seed") = 1u, "Writes a built-in scene as <dir>/<name>.gltf; returns the path.");
}

}  // namespace rtsim::py_bind
