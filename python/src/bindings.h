#pragma once
// Shared declarations of the rtsim._core bindings: the Python-side Scene object and the
// functions that register each part of the module.
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>

#include <pybind11/pybind11.h>

#include "traces/bvh/hw_layout.h"
#include "traces/scene/scene.h"

namespace rtsim::py_bind {

/// A bad argument value: raised in Python as rtsim.errors.ArgumentValueError (an RtsimError
/// and a ValueError), with the message naming the argument.
struct ArgumentError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// A loaded scene as Python sees it. The hardware BVH is built on first use (trace_rays) and
/// cached; the scene itself is immutable once loaded, so arrays handed out can alias it.
class PyScene {
public:
    explicit PyScene(Scene scene) : m_scene(std::move(scene)) {}
    const Scene& scene() const { return m_scene; }
    /// The BVH over the scene, built once (the caller must hold the GIL: it serialises builds).
    const HwBvh& bvh();
    bool has_bvh() const { return m_bvh != nullptr; }

private:
    Scene m_scene;
    std::unique_ptr<HwBvh> m_bvh;
};

void bind_scene(pybind11::module_& m);
void bind_trace(pybind11::module_& m);

}  // namespace rtsim::py_bind
