#pragma once
// What a structure's builder may allocate and how much work it may do, checked by the builder
// before it allocates (a grid's cells and lists from their counts, an octree's nodes and
// references as they grow), so an in-range but absurd setting or a degenerate scene (hundreds of
// overlapping coplanar triangles in an octree) is refused with the figure and the setting to
// change instead of dying in std::bad_alloc, or never ending.
#include <cstdint>
#include <string>

namespace rtsim {

/// Host memory a build may take: half of the physical memory, no more than 80% of what the
/// address-space and data-segment limits (ulimit -v, -d) leave beside what the process already
/// maps, or RTSIM_BUILD_MEMORY_LIMIT_MIB when set (a positive integer of MiB).
uint64_t build_memory_limit_bytes();

/// Throws rtsim::Error "<what> needs about X GiB (<detail>), more than the Y GiB a build may take
/// on this machine (<why>); <advice>" when `bytes` exceeds build_memory_limit_bytes().
void check_build_memory(double bytes, const std::string& what, const std::string& detail, const std::string& advice);

/// "12.3 GiB" / "456.7 MiB": a byte figure for a message.
std::string format_bytes(double bytes);

}  // namespace rtsim
