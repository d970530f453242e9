// SIMT shader-core timing (shader_cores.h).
#include "rtl_model/shading/shader_cores.h"

#include <algorithm>

#include "traces/format/shading_format.h"

namespace rtsim {

ShaderCores::ShaderCores(const ShadingConfig& config, std::vector<MemIf*> tex)
    : m_config(config), m_tex(std::move(tex)), m_issue_free(config.cores, 0), m_resident(config.cores) {}

void ShaderCores::advance_to(Cycle cycle) {
    for (Cycle& c : m_issue_free) c = std::max(c, cycle);
}

WarpResult ShaderCores::run(const std::vector<LaneProgram>& lanes, Cycle ready) {
    WarpResult w;
    // The core whose issue slot frees first (lowest index on ties): warps go where they start soonest.
    uint32_t core = 0;
    for (uint32_t c = 1; c < m_config.cores; ++c)
        if (m_issue_free[c] < m_issue_free[core]) core = c;
    auto& resident = m_resident[core];
    Cycle start = std::max(ready, m_issue_free[core]);
    while (!resident.empty() && resident.top() <= start) resident.pop();
    if (resident.size() >= m_config.warps_resident) {
        start = std::max(start, resident.top());  // wait for a resident warp to finish
        resident.pop();
    }
    // Programs in first-lane order, each run once for its lanes (divergence serialises them).
    std::vector<uint32_t> order;
    for (const LaneProgram& l : lanes)
        if (std::find(order.begin(), order.end(), l.program) == order.end()) order.push_back(l.program);
    Cycle t = start, data = start;
    MemIf* tex = core < m_tex.size() ? m_tex[core] : nullptr;
    for (uint32_t program : order) {
        uint32_t instructions = 0, samples = 0;
        for (const LaneProgram& l : lanes)
            if (l.program == program) {
                instructions = std::max(instructions, l.instructions);
                samples = std::max(samples, l.samples);
                w.lane_instructions += l.instructions + uint64_t(l.samples) * m_config.cost.sample_issue;
            }
        const uint64_t issued = instructions + uint64_t(samples) * m_config.cost.sample_issue;
        // Texture samples issue after the attribute interpolation (a program's first quarter).
        const Cycle sample_at = t + issued / 4 / m_config.issue_per_cycle;
        for (uint32_t s = 0; s < samples && tex; ++s) {
            m_lines.clear();
            for (const LaneProgram& l : lanes) {
                if (l.program != program || s >= l.samples) continue;
                for (uint32_t k = 0; k < kTexelsPerSample; ++k)
                    m_lines.push_back(l.texels[s * kTexelsPerSample + k] & ~uint64_t(m_config.tex_cache.line_bytes - 1));
            }
            std::sort(m_lines.begin(), m_lines.end());
            m_lines.erase(std::unique(m_lines.begin(), m_lines.end()), m_lines.end());
            for (uint64_t line : m_lines) {
                MemRequest req;
                req.addr = line;
                req.bytes = m_config.tex_cache.line_bytes;
                req.kind = DataKind::texture;
                req.time = sample_at + s;
                data = std::max(data, tex->access(req) + m_config.tex_latency);
            }
            w.tex_lines += m_lines.size();
        }
        t += (issued + m_config.issue_per_cycle - 1) / m_config.issue_per_cycle;
        w.issued += issued;
        ++w.programs;
    }
    w.start = start;
    w.issue_end = t;
    w.end = std::max(t, data);
    w.core = core;
    m_issue_busy += t - start;
    m_issue_free[core] = t;  // the next warp issues while this one waits for its texels
    resident.push(w.end);
    return w;
}

}  // namespace rtsim
