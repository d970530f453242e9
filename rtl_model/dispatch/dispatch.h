#pragma once
// Dispatch: hands rays to free ray contexts in trace order, refilling its buffer one chunk at a
// time from a RayStream (the harness streams the trace file; memory stays bounded, rule 8).
#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>
#include <systemc>

#include "rtl_model/common/interfaces.h"
#include "sim/config/config.h"

namespace rtsim {

/// Where rays come from (implemented by the harness over the trace file).
class RayStream {
public:
    virtual ~RayStream() = default;
    /// Appends up to `max` rays in trace order to `out`; returns how many (0 at the end).
    virtual size_t read_chunk(size_t max, std::vector<RayJob>* out) = 0;
    virtual uint64_t total_rays() const = 0;
};

class Dispatch : public sc_core::sc_module, public RaySourceIf {
public:
    Dispatch(sc_core::sc_module_name name, const DispatchConfig& config, RayStream& stream);

    bool next_ray(RayJob* job) override;
    uint64_t total_rays() const override { return m_stream.total_rays(); }
    uint64_t dispatched() const { return m_dispatched; }
    nlohmann::json stats_json() const;

private:
    DispatchConfig m_config;
    RayStream& m_stream;
    std::vector<RayJob> m_buffer;
    size_t m_next = 0;
    uint64_t m_dispatched = 0, m_chunks = 0;
};

}  // namespace rtsim
