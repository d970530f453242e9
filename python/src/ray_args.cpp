#include "python/src/bindings.h"
#include "python/src/ray_args.h"

#include <string>
#include <utility>

#include <pybind11/numpy.h>

namespace py = pybind11;

namespace rtsim::py_bind {
namespace {

using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

/// Refuses what numpy would cast to floats with a loss or a meaning rays do not have: complex
/// numbers (the imaginary part dropped, with only a ComplexWarning), bools, text, objects.
void require_real_numbers(const py::handle& obj, const char* name) {
    py::object array;
    try {
        array = py::module_::import("numpy").attr("asarray")(obj);
    } catch (const py::error_already_set&) {
        return;  // not an array at all (ragged lists): the conversion below names the argument
    }
    const std::string kind = array.attr("dtype").attr("kind").cast<std::string>();
    if (kind == "f" || kind == "i" || kind == "u") return;
    const std::string dtype = py::str(array.attr("dtype")).cast<std::string>();
    throw ArgumentError(std::string(name) + ": expected real numbers (float or integer), got " +
                        (kind == "c" ? "complex numbers" : kind == "b" ? "bools" : "values") + " (dtype " + dtype + ")");
}

/// (N, 3) float array or a ValueError naming the argument.
FloatArray as_vectors(const py::handle& obj, const char* name) {
    require_real_numbers(obj, name);
    FloatArray a = FloatArray::ensure(obj);
    if (!a) throw ArgumentError(std::string(name) + ": expected an array of floats");
    if (a.ndim() != 2 || a.shape(1) != 3) {
        std::string shape = "(";
        for (py::ssize_t i = 0; i < a.ndim(); ++i) shape += (i ? ", " : "") + std::to_string(a.shape(i));
        throw ArgumentError(std::string(name) + ": expected shape (N, 3), got " + shape +
                              (a.ndim() == 1 ? ",)" : ")"));
    }
    return a;
}

/// A scalar (broadcast) or an (N,) array; returns the values and the stride (0 or 1).
std::pair<FloatArray, py::ssize_t> as_limits(const py::handle& obj, py::ssize_t n, const char* name) {
    require_real_numbers(obj, name);
    FloatArray a = FloatArray::ensure(obj);
    if (!a) throw ArgumentError(std::string(name) + ": expected a float or an array of floats");
    if (a.ndim() == 0) return {a, 0};
    if (a.ndim() == 1 && a.shape(0) == n) return {a, 1};
    if (a.ndim() == 1 && a.shape(0) == 1) return {a, 0};
    throw ArgumentError(std::string(name) + ": expected a scalar or shape (" + std::to_string(n) +
                          ",), got an array with " + std::to_string(a.ndim()) + " dimensions and " +
                          std::to_string(a.size()) + " elements");
}

}  // namespace

std::vector<Ray> rays_from_arrays(const py::object& origins, const py::object& directions,
                                  const py::object& tmin, const py::object& tmax) {
    FloatArray o = as_vectors(origins, "origins");
    FloatArray d = as_vectors(directions, "directions");
    const py::ssize_t n = o.shape(0);
    if (d.shape(0) != n) {
        throw ArgumentError("directions: expected " + std::to_string(n) +
                              " rays (as many as origins), got " + std::to_string(d.shape(0)));
    }
    auto [lo, lo_step] = as_limits(tmin, n, "tmin");
    auto [hi, hi_step] = as_limits(tmax, n, "tmax");
    const float* po = o.data();
    const float* pd = d.data();
    std::vector<Ray> rays(static_cast<size_t>(n));
    for (py::ssize_t i = 0; i < n; ++i) {
        Ray& ray = rays[static_cast<size_t>(i)];
        ray.origin = Vec3(po[3 * i], po[3 * i + 1], po[3 * i + 2]);
        ray.direction = Vec3(pd[3 * i], pd[3 * i + 1], pd[3 * i + 2]);
        ray.tmin = lo.data()[i * lo_step];
        ray.tmax = hi.data()[i * hi_step];
    }
    return rays;
}

}  // namespace rtsim::py_bind
