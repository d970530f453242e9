#pragma once
// Errors raised inside the SystemC model reach sc_start() wrapped in an sc_report ("Error:
// (E549) uncaught exception: ...  In file: kernel/sc_except.cpp"). These helpers turn one back
// into a message naming the trace and, for a traversal failure, the ray, so rtsim-sim reports
// it as bad input (exit 2) like any other.
#include <string>

#include "traces/accel/accel.h"
#include "traces/format/trace_reader.h"

namespace rtsim {

/// The original message of an error wrapped by SystemC (the report text without its
/// "Error: (E549) uncaught exception:" prefix and "In file:" / "In process:" lines).
std::string unwrap_report(const std::string& report);

/// Replays the trace's rays through the structure's reference traversal (Accel::trace) and returns
/// "ray N: <error>" for the first ray whose traversal throws rtsim::Error (a traversal stack
/// overflow, say), or "" when every ray traverses. O(rays); only used on the error path.
std::string first_failing_ray(const Accel& accel, TraceReader& reader);

}  // namespace rtsim
