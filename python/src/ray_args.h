#pragma once
// Rays from numpy arguments, shared by trace_rays and write_trace: origins and directions as
// (N, 3) float arrays, tmin and tmax as scalars or (N,) arrays. Bad shapes raise ValueError
// naming the argument.
#include <vector>

#include <pybind11/pybind11.h>

#include "traces/common/ray.h"

namespace rtsim::py_bind {

std::vector<Ray> rays_from_arrays(const pybind11::object& origins, const pybind11::object& directions,
                                  const pybind11::object& tmin, const pybind11::object& tmax);

}  // namespace rtsim::py_bind
