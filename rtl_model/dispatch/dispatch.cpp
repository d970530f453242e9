#include "rtl_model/dispatch/dispatch.h"

namespace rtsim {

Dispatch::Dispatch(sc_core::sc_module_name name, const DispatchConfig& config, RayStream& stream)
    : sc_core::sc_module(name), m_config(config), m_stream(stream) {}

bool Dispatch::next_ray(RayJob* job) {
    if (m_next == m_buffer.size()) {
        m_buffer.clear();
        m_next = 0;
        if (m_stream.read_chunk(m_config.chunk_rays, &m_buffer) == 0) return false;
        ++m_chunks;
    }
    *job = m_buffer[m_next++];
    ++m_dispatched;
    return true;
}

nlohmann::json Dispatch::stats_json() const {
    return {{"rays", m_dispatched}, {"chunks", m_chunks}, {"chunk_rays", m_config.chunk_rays}};
}

}  // namespace rtsim
