#pragma once
// Wall-clock timing of builds and traces (the manifests' *_ms fields).
#include <chrono>

namespace rtsim {

/// Milliseconds of wall time since `t0`.
inline double ms_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace rtsim
