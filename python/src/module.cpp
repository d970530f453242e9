// rtsim._core: the C++ reference tracer seen from Python. rtsim::Error becomes
// rtsim.RtsimError (a RuntimeError) so bad input reads as a message, not a crash.
#include <pybind11/pybind11.h>

#include "python/src/bindings.h"
#include "traces/common/build_info.h"
#include "traces/common/error.h"

namespace py = pybind11;

PYBIND11_MODULE(_core, m) {
    m.doc() = "rtsim reference tracer bindings (scenes, rays, traces)";
    py::register_exception<rtsim::Error>(m, "RtsimError", PyExc_RuntimeError);
    m.attr("__version__") = rtsim::rtsim_version();
    m.attr("git_hash") = rtsim::rtsim_git_hash();
    m.attr("default_scenes_dir") = RTSIM_DEFAULT_SCENES;
    rtsim::py_bind::bind_scene(m);
    rtsim::py_bind::bind_trace(m);
}
