#pragma once
// An acceleration-structure image in a trace file (docs/trace_format.md): section ACCL holds
// the descriptor (AccelImage::descriptor(), JSON text), section RGnn region n's records.
#include "traces/accel/accel_image.h"
#include "traces/format/trace_reader.h"
#include "traces/format/trace_writer.h"

namespace rtsim {

void write_accel_image(TraceWriter& writer, const AccelImage& image);

/// Reads the descriptor alone (kind, params, stats, bounds, the regions' shapes): the JSON of
/// AccelImage::descriptor(). Throws rtsim::Error naming the file when it is missing or malformed.
nlohmann::json read_accel_descriptor(TraceReader& reader);
/// Reads the descriptor and every region (each chunk's CRC checked). Throws rtsim::Error naming
/// the file and the section or field when something is missing, malformed or inconsistent.
AccelImage read_accel_image(TraceReader& reader);

}  // namespace rtsim
