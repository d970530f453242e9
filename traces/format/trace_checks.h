#pragma once
// Checks of a trace's records that every reader makes (rtsim-sim and rtsim.open_trace alike),
// beyond the header, table and CRCs the TraceReader checks: the per-ray sections agree in
// length, and an animated trace's frame table covers its rays back to back.
#include <cstdint>
#include <vector>

#include "traces/format/trace_format.h"
#include "traces/format/trace_reader.h"

namespace rtsim {

/// Throws rtsim::Error naming the trace unless RAYS, HITS and WORK are present with one record
/// per ray each.
void check_ray_sections(const TraceReader& reader);

/// The trace's frames: its FRMS records, or one frame of every ray when it has none. Throws
/// rtsim::Error naming the trace unless the frames are back to back, cover every ray and match
/// the structure's frame count (`accel_frames`).
std::vector<FrameRecord> read_frame_table(TraceReader& reader, uint32_t accel_frames);

}  // namespace rtsim
