// The shading block's stats (model.shading), declared once (docs/stats.md is generated from them).
#include "rtl_model/shading/shading_block.h"

namespace rtsim {

using nlohmann::json;

const StatBlock& shading_stats() {
    static const StatBlock block{
        "model.shading",
        {
            {"frame_loop", "", "`wavefront` (trace a bounce, shade it, generate the next) or `inflight`"},
            {"reorder", "", "The sorting stage's key before warps form (`none`: completion order)"},
            {"frame_cycles", "cycles", "Frame time: ray generation to the last ray shaded", true},
            {"frame_ms", "ms", "Frame time at the clock", true},
            {"breakdown", "cycles", "`{raygen, build, traversal, reorder, shading}`, summing to `frame_cycles` (build: an animated trace's waits for the build unit beyond the next frame's ray generation, wavefront loop; inflight: traversal spans the RT unit's busy period, shading the tail after it, each summed over an animated trace's frames with their ray generation and build waits)", true},
            {"stalls", "cycles", "wavefront loop: `{rt_waits_for_shading, cores_wait_for_traversal, shading_texture_bound}`: the RT unit idle while a bounce is generated, sorted and shaded; the shader cores idle while it is traced; the part of shading the cores' issue does not explain (waiting for texels). Absent in flight (the two overlap)", true, true},
            {"shading_share", "", "Fraction of the frame not in traversal (raygen + reorder + shading) / frame", true},
            {"amdahl", "", "`{traversal_share, speedup_2x_rt, speedup_infinite_rt}`: what a 2x (or infinitely) faster RT unit buys the frame with shading unchanged", true},
            {"rays", "rays", "Rays shaded (every ray of the trace, once)"},
            {"hits", "rays", "Path rays that hit: hit shaders run"},
            {"misses", "rays", "Path rays that missed: miss shaders run"},
            {"shadow", "rays", "Shadow rays whose answer a shader consumed"},
            {"warps", "warps", "Warps shaded (ray generation aside)"},
            {"divergence", "programs/warp", "Mean distinct programs per warp (1: none; SIMT runs them one after another)"},
            {"simd_efficiency", "", "Hit, miss and shadow programs' lane instructions needed / lane slots issued (Aila & Laine 2009's SIMD efficiency)"},
            {"warp_instructions", "instructions", "Warp instructions issued, ray generation included"},
            {"lane_instructions", "instructions", "Instructions the lanes needed, ray generation included"},
            {"texture_samples", "samples", "Texture samples of hit shaders (4 texels each)"},
            {"tex_lines", "lines", "Texture-cache line reads (texels coalesced per sample instruction)"},
            {"texture_model", "", "The texture caches built, or why none (a scene that samples no texture)"},
            {"tex_hit_rate", "", "Texture caches' hit rate over every core's cache; null without a texture model", true},
            {"reorder_sorted", "rays", "Hits through the sorting stage"},
            {"reorder_buffer_bytes", "bytes", "Sorting buffer SRAM (window x entry bytes); 0 without a sorting stage"},
            {"core_utilization", "", "Issue slots used / (cores x frame cycles)", true},
            {"texel_mismatches", "rays", "Rays whose texel addresses differ from the reference tracer's (0 allowed)"},
            {"order_violations", "rays", "Rays that started before their parent was shaded, or reached shading twice (0 allowed)"},
            {"first_texel_mismatch", "", "The first such ray, or empty"},
            {"energy_pj", "pJ", "Shader cores' energy: lane instructions, texture samples, sorting (caches and DRAM are counted by their levels)"},
            {"area_mm2", "mm^2", "Shader cores' area (cores x core_mm2)"},
            {"max_pending", "rays", "Most finished rays waiting to be shaded at once (the hit buffer's high-water mark)"},
            {"tex_caches", "", "Each texture cache's stats (a cache's keys, as `model.l2`), by instance name; absent without a texture model", false, true},
            {"wavefronts", "", "wavefront loop: per bounce `{wavefront, rays, traversal_cycles, reorder_cycles, shading_cycles, warps, divergence, simd_efficiency, warp_instructions, tex_lines}`", false, true},
        }};
    return block;
}
RTSIM_REGISTER_STAT_BLOCK(shading_stats)

json ShadingBlock::stats_json(Cycle rt_end, double clock_ghz) const {
    const Cycle frame = frame_end(rt_end);
    json breakdown;
    if (m_config.frame_loop == FrameLoop::wavefront) {
        breakdown = {{"raygen", m_raygen_cycles}, {"build", m_build}, {"traversal", m_traversal}, {"reorder", m_reorder},
                     {"shading", m_shading}};
    } else if (m_frames_ended > 0) {
        // An animated trace: per frame its camera rays' generation, the wait for its builds, its
        // RT span (shading overlapped) and the shading tail after its last ray, summed.
        breakdown = {{"raygen", m_raygen_cycles}, {"build", m_build}, {"traversal", m_inflight_rt}, {"reorder", 0},
                     {"shading", m_inflight_tail}};
    } else {
        const Cycle rt = std::max(rt_end, m_raygen_end);
        breakdown = {{"raygen", m_raygen_end}, {"build", 0}, {"traversal", rt - m_raygen_end}, {"reorder", 0},
                     {"shading", frame - rt}};
    }
    const double traversal = breakdown["traversal"].get<double>();
    const double share = frame ? traversal / double(frame) : 0.0;
    MemCounters tex;
    for (const auto& c : m_tex) tex += c->stats()[DataKind::texture];
    json j;
    StatsWriter w(shading_stats(), j);
    w.set("frame_loop", kFrameLoopChoices.name(m_config.frame_loop))
        .set("reorder", kShadeReorderChoices.name(m_config.reorder))
        .set("frame_cycles", frame)
        .set("frame_ms", double(frame) / (clock_ghz * 1e6))
        .set("breakdown", breakdown)
        .set("shading_share", frame ? 1.0 - share : 0.0)
        .set("amdahl", json{{"traversal_share", share},
                            {"speedup_2x_rt", 1.0 / (1.0 - share / 2.0)},
                            {"speedup_infinite_rt", share < 1.0 ? 1.0 / (1.0 - share) : 0.0}})
        .set("rays", m_shaded)
        .set("hits", m_hits)
        .set("misses", m_misses)
        .set("shadow", m_shadow)
        .set("warps", m_warps)
        .set("divergence", m_warps ? double(m_programs) / double(m_warps) : 0.0)
        .set("simd_efficiency", m_lane_slots ? double(m_lane_instructions) / double(m_lane_slots) : 0.0)
        .set("warp_instructions", m_issued + m_raygen_issued)
        .set("lane_instructions", m_lane_instructions + m_raygen_lane_instructions)
        .set("texture_samples", m_samples)
        .set("tex_lines", m_tex_lines)
        .set("texture_model", m_tex.empty() ? std::string(m_in.has_textures() ? "ideal memory: texels at no cost"
                                                                              : "no material samples a texture: no texture caches")
                                            : std::to_string(m_tex.size()) + " texture caches of " +
                                                  std::to_string(m_config.tex_cache.size_kib) + " KiB into the L2")
        .set("tex_hit_rate", m_tex.empty() || !tex.reads ? json(nullptr) : json(double(tex.read_hits) / double(tex.reads)))
        .set("reorder_sorted", m_sorted)
        .set("reorder_buffer_bytes", m_config.reorder == ShadeReorder::none
                                         ? 0
                                         : uint64_t(m_config.reorder_window) * m_config.reorder_entry_bytes)
        .set("core_utilization", frame ? double(m_cores->issue_busy()) / (double(m_config.cores) * double(frame)) : 0.0)
        .set("texel_mismatches", m_texel_mismatches)
        .set("order_violations", order_violations())
        .set("first_texel_mismatch", m_first_mismatch)
        .set("energy_pj", double(m_lane_instructions + m_raygen_lane_instructions) * m_config.alu_pj + double(m_samples) * m_config.tex_sample_pj +
                              double(m_sorted) * m_config.reorder_pj)
        .set("area_mm2", m_config.cores * m_config.core_mm2)
        .set("max_pending", m_max_pending);
    if (m_config.frame_loop == FrameLoop::wavefront) {
        w.set("wavefronts", m_wavefronts);
        w.set("stalls", json{{"rt_waits_for_shading", m_raygen_cycles + m_reorder + m_shading},
                             {"cores_wait_for_traversal", m_traversal},
                             {"shading_texture_bound", m_texture_bound}});
    }
    if (!m_tex.empty()) {
        json caches = json::object();
        for (const auto& c : m_tex) caches[c->basename()] = c->stats_json(frame);
        w.set("tex_caches", caches);
    }
    w.done();
    return j;
}

}  // namespace rtsim
