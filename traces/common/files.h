#pragma once
// Checks of the paths a user hands rtsim, made before anything is opened or written: a FIFO
// would block an open and a device (/dev/zero) read without end; a path that is not UTF-8
// cannot be recorded in the JSON manifests and provenance; an output folder that cannot be
// made is named, not left to a std::filesystem_error. Each throws rtsim::Error naming the path.
#include <cstdint>
#include <string>

namespace rtsim {

/// `path` must name an existing regular file (symbolic links followed); `what` says what it
/// should be ("trace file", "config JSON file").
void require_regular_file(const std::string& path, const std::string& what);

/// `path` must be well-formed UTF-8 (rtsim writes paths into JSON); `what` names the argument.
void require_utf8_path(const std::string& path, const std::string& what);

/// Creates folder `path` (and its parents) unless it exists; refuses a file in the way, a
/// folder that cannot be made or written (read-only, /proc). `what` names the argument.
void make_output_folder(const std::string& path, const std::string& what);

/// The whole of a regular file of at most `max_bytes` (require_regular_file first).
std::string read_small_file(const std::string& path, const std::string& what, uint64_t max_bytes);

}  // namespace rtsim
