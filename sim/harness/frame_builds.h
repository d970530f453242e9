#pragma once
// Moving scenes in the harness (docs/model.md, "Build unit"): each frame's build jobs, read from
// the frame records a two-level image carries (traces/accel/two_level/two_level.h: a frame's
// "build": the BLASes it built or refitted and its TLAS), with the byte ranges each writes (the
// structure's regions at its addresses) and reads (its triangle records: the vertices the
// skinning or the animation left there).
#include <functional>
#include <vector>

#include "rtl_model/build_unit/build_unit.h"
#include "traces/accel/accel.h"

namespace rtsim {

/// Per frame, the jobs the build unit runs before its rays (frame 0: none, its structures exist
/// before the run); empty when the image records no builds (one frame, or an older trace).
std::vector<std::vector<BuildJob>> frame_build_jobs(const Accel& accel);

/// The jobs moved to a second buffer (build_unit.overlap): a build beside the previous frame's
/// rays writes the next frame's structures elsewhere than the ones those rays read, so its
/// lines take the L2's room and bandwidth without serving the traversal. The model's traversal
/// addresses stand for the buffer in use; the next frame's rays then find the lines the previous
/// frame's rays left (not the ones the build wrote).
void move_to_second_buffer(std::vector<std::vector<BuildJob>>& jobs);

/// When each frame's structures are built (docs/model.md, "Build unit"). Serially (the default):
/// at the barrier before the frame, from the previous frame's end, while no ray runs. With
/// build_unit.overlap (async compute, two buffers): frame f+1's build starts when frame f's
/// structures are ready and frame f-1's rays are done (its buffer is free), beside frame f's
/// rays; a frame starts when the frame before it has ended and its own build is done.
class FrameBuildSchedule {
public:
    /// Starts frame f's builds from cycle `at` (a frame that builds nothing: none).
    using StartFn = std::function<void(uint32_t f, Cycle at)>;
    /// Frame f's builds, started: when they are done (their start when there were none).
    using FinishFn = std::function<Cycle(uint32_t f)>;
    /// With `overlap` frame 1's build starts at once, from cycle 0, beside frame 0's rays.
    FrameBuildSchedule(bool overlap, uint32_t frames, StartFn start, FinishFn finish);
    /// The cycle frame f (f >= 1) may start, the frame before it having ended at `end`.
    Cycle ready(uint32_t f, Cycle end);

private:
    bool m_overlap;
    uint32_t m_frames;
    StartFn m_start;
    FinishFn m_finish;
};

}  // namespace rtsim
