#pragma once
// Moving scenes in the harness (docs/model.md, "Build unit"): each frame's build jobs, read from
// the frame records a two-level image carries (traces/accel/two_level/two_level.h: a frame's
// "build": the BLASes it built or refitted and its TLAS), with the byte ranges each writes (the
// structure's regions at its addresses) and reads (its triangle records: the vertices the
// skinning or the animation left there).
#include <vector>

#include "rtl_model/build_unit/build_unit.h"
#include "traces/accel/accel.h"

namespace rtsim {

/// Per frame, the jobs the build unit runs before its rays (frame 0: none, its structures exist
/// before the run); empty when the image records no builds (one frame, or an older trace).
std::vector<std::vector<BuildJob>> frame_build_jobs(const Accel& accel);

}  // namespace rtsim
