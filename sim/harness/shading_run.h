#pragma once
// The frame in the harness (docs/shading.md): the shading block's inputs read from a version-5
// trace, the wavefront loop's bounces as dispatch barriers, and the in-flight loop's parent gate.
#include <cstdint>
#include <memory>
#include <vector>

#include "rtl_model/shading/shading_inputs.h"
#include "rtl_model/top/top.h"
#include "sim/config/config.h"
#include "traces/format/trace_reader.h"

namespace rtsim {

/// The trace's shading tables, every ray's record and shading record, the reference texel
/// addresses and the wavefronts; null when shading.enabled is false or the trace has no shading
/// sections (the resolution step lists the setting as unused then).
std::unique_ptr<ShadingInputs> load_shading_inputs(TraceReader& reader, const SimConfig& config);
/// The wavefronts as stream segments (each a run of rays of one depth, in trace order).
std::vector<FrameRecord> wavefront_segments(const ShadingInputs& inputs);
/// Wires the frame loop into dispatch: no ray before ray generation ends; wavefront: a barrier
/// per bounce released when the shading block has shaded it (`on_frame(f, cycle)`: frame f's last
/// bounce shaded; an animated trace's next frame then generates its camera rays); inflight: rays
/// wait for their parent's warp.
/// `build(first, last, at)`: an animated trace's frames first..last build their structures from
/// `at` on the build unit and return when the last is built (wavefront, between frames; none
/// without a build unit).
using FrameBuilds = std::function<Cycle(uint32_t first, uint32_t last, Cycle at)>;
void wire_frame_loop(Top& top, const ShadingConfig& config, const ShadingInputs& inputs,
                     std::function<void(uint32_t, Cycle)> on_frame, FrameBuilds build = nullptr);

}  // namespace rtsim
