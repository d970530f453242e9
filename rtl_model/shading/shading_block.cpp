// The shading block (shading_block.h): programs per ray, warps, the sorting stage, the frame.
#include "rtl_model/shading/shading_block.h"

#include <algorithm>
#include <numeric>

#include "traces/shading/texels.h"

namespace rtsim {

using nlohmann::json;

namespace {

/// Instructions of a hit shader with `features` (MaterialRecord::features bits).
uint32_t hit_instructions(const ShaderCosts& c, uint32_t f) {
    const uint32_t part[] = {c.base_color_tex, c.normal_tex, c.metal_rough_tex, c.emissive_tex, c.occlusion_tex,
                             c.alpha_mask,     c.alpha_blend, c.transmission,   c.metallic,     c.emissive};
    uint32_t n = c.hit_base;
    for (size_t b = 0; b < sizeof(part) / sizeof(part[0]); ++b)
        if (f & (1u << b)) n += part[b];
    return n;
}

uint8_t octant(const float* d) { return uint8_t((d[0] < 0) | (d[1] < 0) << 1 | (d[2] < 0) << 2); }

double ratio(double a, double b) { return b > 0 ? a / b : 0.0; }

}  // namespace

ShadingBlock::ShadingBlock(sc_core::sc_module_name name, const ShadingConfig& config, const ShadingInputs& inputs,
                           RaySinkIf& downstream, MemIf* l2, Cycle interconnect_latency, bool detailed)
    : sc_core::sc_module(name), m_config(config), m_in(inputs), m_downstream(downstream) {
    std::vector<MemIf*> tex;
    // A scene that samples no texture gets no texture caches (rule 10: only what it calls for).
    if (inputs.has_textures() && l2)
        for (uint32_t c = 0; c < config.cores; ++c) {
            m_tex.push_back(std::make_unique<Cache>(("tex" + std::to_string(c)).c_str(), config.tex_cache, true,
                                                    interconnect_latency, detailed));
            m_tex.back()->next(*l2);
            tex.push_back(m_tex.back().get());
        }
    m_cores = std::make_unique<ShaderCores>(config, tex);
    m_shaded_at.assign(inputs.rays.size(), 0);
    m_done.assign(inputs.rays.size(), 0);
    m_seen.assign(inputs.rays.size(), 0);
    // The first frame's camera rays are generated before any traversal.
    // (An animated trace's: the first frame with rays, leading empty frames aside.)
    const FrameRecord first = inputs.frames.empty() || inputs.wavefront_frame.empty()
                                  ? FrameRecord{0, inputs.rays.size()}
                                  : inputs.frames[inputs.wavefront_frame[0]];
    m_raygen_end = raygen(first.first_ray, first.rays, 0);
    m_release = m_last_end = m_raygen_end;
}

ShadingBlock::~ShadingBlock() = default;

Cycle ShadingBlock::raygen(uint64_t first, uint64_t rays, Cycle at) {
    // Primary rays are generated in warps before their frame's first wavefront (the camera's program).
    const uint32_t program = m_in.shaders + 2;
    uint64_t primaries = 0;
    for (uint64_t i = first; i < first + rays && i < m_in.rays.size(); ++i)
        primaries += m_in.rays[i].kind == uint8_t(RayKind::primary);
    std::vector<LaneProgram> lanes;
    Cycle end = at;
    for (uint64_t i = 0; i < primaries; i += m_config.warp_width) {
        lanes.assign(std::min<uint64_t>(m_config.warp_width, primaries - i), LaneProgram{program, m_config.cost.raygen});
        const WarpResult w = m_cores->run(lanes, at);
        end = std::max(end, w.end);
        m_raygen_issued += w.issued, m_raygen_lane_instructions += w.lane_instructions;
    }
    m_raygen_cycles += end - at;
    return end;
}

Cycle ShadingBlock::begin_frame(uint32_t f, Cycle at) {
    m_cores->advance_to(at);
    const Cycle end = raygen(m_in.frames.at(f).first_ray, m_in.frames[f].rays, at);
    m_release = end;
    m_last_end = std::max(m_last_end, end);
    return end;
}

Cycle ShadingBlock::await_build(Cycle built) {
    if (built > m_release) {
        m_build += built - m_release;
        m_release = built;
        m_last_end = std::max(m_last_end, built);
    }
    return m_release;
}

ShadingBlock::Lane ShadingBlock::lane_of(const RayResult& r) {
    const RayRecord& ray = m_in.rays[r.id];
    const ShadeRecord& ref = m_in.shade[r.id];
    Lane l{r.id, r.end, {}, 0xFFFFFFFFu, octant(ray.direction), uint32_t(m_texels.size())};
    // Dependency order: a ray starts only after its parent was shaded, and is shaded once.
    const int64_t parent = ref.parent;
    if (parent >= 0 && (!m_done[size_t(parent)] || r.start < m_shaded_at[size_t(parent)])) ++m_order_violations;
    if (m_done[r.id] || m_seen[r.id]) ++m_shaded_twice;
    m_seen[r.id] = 1;
    if (ray.flags & kRayFlagAnyHit) {
        l.program = {m_in.shaders + 1, m_config.cost.shadow_result};
        ++m_shadow;
        return l;
    }
    if (!r.hit.valid() || size_t(r.hit.prim) >= m_in.tris.size()) {
        l.program = {m_in.shaders, m_config.cost.miss};
        l.key_material = 0xFFFFFFFEu;
        ++m_misses;
        return l;
    }
    const TriShadeRecord& tri = m_in.tris[size_t(r.hit.prim)];
    const MaterialRecord& m = m_in.materials[tri.material];
    // The texels this hit's shader reads, from the model's own hit, checked against the reference.
    const Vec3 dir(ray.direction[0], ray.direction[1], ray.direction[2]);
    const uint32_t samples =
        hit_texels(m_in.materials, m_in.textures, tri, r.hit, dir, RayCone{ref.cone_width, ref.cone_spread}, &m_texels);
    bool same = samples == ref.samples && ref.first_fetch + uint64_t(samples) * kTexelsPerSample <= m_in.reference_fetches.size();
    for (uint32_t k = 0; same && k < samples * kTexelsPerSample; ++k)
        same = m_texels[l.texel_offset + k] == m_in.reference_fetches[ref.first_fetch + k];
    if (!same) {
        if (!m_texel_mismatches)
            m_first_mismatch = "ray " + std::to_string(r.id) + ": " + std::to_string(samples) + " texture samples, reference " +
                               std::to_string(ref.samples) + " (or their texel addresses differ)";
        ++m_texel_mismatches;
    }
    l.program = {m.shader, hit_instructions(m_config.cost, m.features), samples, nullptr};
    l.key_material = tri.material;
    m_samples += samples;
    ++m_hits;
    return l;
}

void ShadingBlock::ray_done(const RayResult& r) {
    m_downstream.ray_done(r);
    m_pending.push_back(lane_of(r));
    m_max_pending = std::max<uint64_t>(m_max_pending, m_pending.size());
    if (m_config.frame_loop != FrameLoop::inflight) return;
    // inflight: a warp (or a sorting window) is shaded as soon as it is full, or when it waited
    // form_timeout cycles, or when the RT unit has nothing left in flight to add to it.
    const size_t batch = m_config.reorder == ShadeReorder::none ? m_config.warp_width : m_config.reorder_window;
    const bool late = m_pending.front().ready + m_config.form_timeout <= r.end;
    if (m_pending.size() >= batch || late || (rt_idle && rt_idle())) flush_inflight(r.end);
}

void ShadingBlock::packet_done(const RayResult* results, const Ray* rays, const TraversalMode* modes, uint32_t n) {
    m_downstream.packet_done(results, rays, modes, n);
    // The checker saw the packet; shading sees each ray (forwarding them again would check twice).
    for (uint32_t i = 0; i < n; ++i) {
        m_pending.push_back(lane_of(results[i]));
        m_max_pending = std::max<uint64_t>(m_max_pending, m_pending.size());
    }
    if (m_config.frame_loop == FrameLoop::inflight) flush_inflight(results[n - 1].end);
}

void ShadingBlock::flush_inflight(Cycle now) {
    if (m_pending.empty()) return;
    Cycle ready = now;
    for (const Lane& l : m_pending) ready = std::max(ready, l.ready);
    const Cycle end = shade(m_pending, ready, m_config.reorder != ShadeReorder::none);
    m_last_end = std::max(m_last_end, end);
    m_shaded_ids.clear();
    for (const Lane& l : m_pending) m_shaded_ids.push_back(l.id);
    m_pending.clear();
    m_texels.clear();
    if (on_shaded) on_shaded(m_shaded_ids);
}

Cycle ShadingBlock::shade(std::vector<Lane>& lanes, Cycle ready, bool sort) {
    for (Lane& l : lanes) l.program.texels = m_texels.data() + l.texel_offset;
    if (!sort) {
        run_warps(lanes, 0, lanes.size(), ready);
        Cycle end = ready;
        for (const Lane& l : lanes) end = std::max(end, m_shaded_at[l.id]);
        return end;
    }
    // The sorting stage: windows of reorder_window hits stream in at reorder_rays_per_cycle, each
    // sorted by its key and out after reorder_latency; shading starts window by window.
    auto key = [&](const Lane& l) -> uint64_t {
        switch (m_config.reorder) {
        case ShadeReorder::shader: return l.program.program;
        case ShadeReorder::material: return l.key_material;
        case ShadeReorder::material_direction: return uint64_t(l.key_material) << 3 | l.octant;
        case ShadeReorder::none: break;
        }
        return 0;
    };
    Cycle end = ready, in = ready;
    for (size_t first = 0; first < lanes.size(); first += m_config.reorder_window) {
        const size_t last = std::min(lanes.size(), first + m_config.reorder_window);
        std::stable_sort(lanes.begin() + long(first), lanes.begin() + long(last),
                         [&](const Lane& a, const Lane& b) { return key(a) < key(b); });
        in += (last - first + m_config.reorder_rays_per_cycle - 1) / m_config.reorder_rays_per_cycle;
        const Cycle out = in + m_config.reorder_latency;
        if (first == 0) m_reorder_exposed = out - ready;
        m_sorted += last - first;
        run_warps(lanes, first, last, out);
        for (size_t i = first; i < last; ++i) end = std::max(end, m_shaded_at[lanes[i].id]);
    }
    return end;
}

void ShadingBlock::run_warps(std::vector<Lane>& lanes, size_t first, size_t end, Cycle ready) {
    std::vector<LaneProgram> warp;
    for (size_t i = first; i < end; i += m_config.warp_width) {
        const size_t n = std::min<size_t>(m_config.warp_width, end - i);
        warp.clear();
        for (size_t k = 0; k < n; ++k) warp.push_back(lanes[i + k].program);
        const WarpResult w = m_cores->run(warp, ready);
        for (size_t k = 0; k < n; ++k) {
            m_shaded_at[lanes[i + k].id] = w.end;
            m_done[lanes[i + k].id] = 1;
        }
        ++m_warps;
        m_programs += w.programs;
        m_issued += w.issued;
        m_lane_instructions += w.lane_instructions;
        m_lane_slots += w.issued * m_config.warp_width;
        m_tex_lines += w.tex_lines;
        m_shaded += n;
    }
}

Cycle ShadingBlock::wavefront_end(uint32_t w, Cycle end) {
    // Rays of a wavefront start at its release; it is traced until `end`, then shaded.
    const uint64_t warps0 = m_warps, programs0 = m_programs, issued0 = m_issued, slots0 = m_lane_slots;
    const uint64_t useful0 = m_lane_instructions, lines0 = m_tex_lines, rays = m_pending.size();
    const uint64_t busy0 = m_cores->issue_busy();
    m_reorder_exposed = 0;
    m_cores->advance_to(end);
    const Cycle shaded = m_pending.empty() ? end : shade(m_pending, end, m_config.reorder != ShadeReorder::none);
    m_pending.clear();
    m_texels.clear();
    const uint64_t traversal = end > m_release ? end - m_release : 0, reorder = std::min(m_reorder_exposed, shaded - end);
    m_traversal += traversal;
    m_reorder += reorder;
    m_shading += shaded - end - reorder;
    // Of the shading span, what the cores' issue slots (spread over every core) do not explain
    // waited on texels: the texture-bound part.
    const uint64_t issue_bound = (m_cores->issue_busy() - busy0) / m_config.cores;
    m_texture_bound += shaded - end - reorder > issue_bound ? shaded - end - reorder - issue_bound : 0;
    m_wavefronts.push_back({{"wavefront", w},
                            {"rays", rays},
                            {"traversal_cycles", traversal},
                            {"reorder_cycles", reorder},
                            {"shading_cycles", shaded - end - reorder},
                            {"warps", m_warps - warps0},
                            {"divergence", ratio(double(m_programs - programs0), double(m_warps - warps0))},
                            {"simd_efficiency", ratio(double(m_lane_instructions - useful0), double(m_lane_slots - slots0))},
                            {"warp_instructions", m_issued - issued0},
                            {"tex_lines", m_tex_lines - lines0}});
    m_release = shaded;
    m_last_end = std::max(m_last_end, shaded);
    return shaded;
}

Cycle ShadingBlock::end_frame_inflight(Cycle end) {
    // The frame's hits still forming a warp are shaded now: nothing of this frame is left to join them.
    flush_inflight(end);
    const Cycle shaded = std::max(end, m_last_end);
    m_inflight_rt += end > m_release ? end - m_release : 0;
    m_inflight_tail += shaded - std::max(end, m_release);
    ++m_frames_ended;
    m_release = shaded;
    return shaded;
}

bool ShadingBlock::parent_shaded(uint64_t id, Cycle* not_before) const {
    const int64_t parent = id < m_in.shade.size() ? m_in.shade[id].parent : -1;
    if (parent < 0) {
        *not_before = m_raygen_end;
        return true;
    }
    if (!m_done[size_t(parent)]) return false;
    *not_before = m_shaded_at[size_t(parent)];
    return true;
}

uint64_t ShadingBlock::parent_of(uint64_t id) const {
    return id < m_in.shade.size() && m_in.shade[id].parent >= 0 ? uint64_t(m_in.shade[id].parent) : id;
}

Cycle ShadingBlock::frame_end(Cycle rt_end) const { return std::max(rt_end, m_last_end); }

}  // namespace rtsim
