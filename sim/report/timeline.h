#pragma once
// Chrome / Perfetto trace-event timeline of a run (rtsim simulate --timeline): one track per ray
// context showing which ray it traced when, and a DRAM bandwidth counter. Open the file in
// https://ui.perfetto.dev or chrome://tracing. Ray spans are kept for the first kMaxRays rays.
#include <cstdint>
#include <string>
#include <vector>

#include "rtl_model/common/interfaces.h"

namespace rtsim {

class Timeline {
public:
    static constexpr size_t kMaxRays = 50000;
    explicit Timeline(double clock_ghz) : m_clock_ghz(clock_ghz) {}
    void ray(const RayResult& r, uint8_t kind);
    /// Writes the trace-event JSON; dram_bytes: bytes per bucket of bucket_cycles.
    void write(const std::string& path, uint32_t units, const std::vector<uint64_t>& dram_bytes,
               uint64_t bucket_cycles) const;

private:
    struct Span {
        uint64_t start, end, id;
        uint32_t unit, context;
        uint8_t kind;
    };
    double m_clock_ghz;
    std::vector<Span> m_spans;
};

}  // namespace rtsim
