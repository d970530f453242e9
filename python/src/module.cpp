// rtsim._core: the C++ reference tracer seen from Python. rtsim::Error becomes
// rtsim.RtsimError (a RuntimeError, defined in rtsim/errors.py so Python code can raise and
// catch it without loading this module) so bad input reads as a message, not a crash.
#include <pybind11/pybind11.h>

#include "python/src/bindings.h"
#include "traces/common/build_info.h"
#include "traces/common/error.h"

namespace py = pybind11;

PYBIND11_MODULE(_core, m) {
    m.doc() = "rtsim reference tracer bindings (scenes, rays, traces)";
    // Leaked on purpose: the translator may run until the interpreter exits.
    static py::handle rtsim_error =
        py::object(py::module_::import("rtsim.errors").attr("RtsimError")).release();
    static py::handle argument_error =
        py::object(py::module_::import("rtsim.errors").attr("ArgumentValueError")).release();
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const rtsim::Error& e) {
            PyErr_SetString(rtsim_error.ptr(), e.what());
        } catch (const rtsim::py_bind::ArgumentError& e) {
            PyErr_SetString(argument_error.ptr(), e.what());
        }
    });
    m.attr("RtsimError") = rtsim_error;
    m.attr("__version__") = rtsim::rtsim_version();
    m.attr("git_hash") = rtsim::rtsim_git_hash();
    m.attr("default_scenes_dir") = RTSIM_DEFAULT_SCENES;
    rtsim::py_bind::bind_scene(m);
    rtsim::py_bind::bind_trace(m);
}
