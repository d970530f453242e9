#pragma once
// The shading block (docs/shading.md): every finished ray passes through it on its way to the hit
// checker. It runs each ray's program (ray generation, its hit or miss shader, the shadow result)
// on the SIMT shader cores, its texture samples through the cores' texture caches into the shared
// L2, optionally regrouped by a sorting stage first (NVIDIA SER, Intel's thread sorting unit),
// and decides when a ray's children may start: after the whole bounce is shaded (wavefront) or
// after the ray's own warp is (inflight). It checks every texel address it issues against the
// reference tracer's and accounts the frame: its time and where it went.
#include <cstdint>
#include <memory>
#include <vector>

#include <nlohmann/json.hpp>
#include <systemc>

#include "rtl_model/common/interfaces.h"
#include "rtl_model/common/stats.h"
#include "rtl_model/mem/cache.h"
#include "rtl_model/shading/shader_cores.h"
#include "rtl_model/shading/shading_config.h"
#include "rtl_model/shading/shading_inputs.h"

namespace rtsim {

const StatBlock& shading_stats();

class ShadingBlock : public sc_core::sc_module, public RaySinkIf {
public:
    /// `l2`: the shared L2 the texture caches miss into (null with ideal memory: texels at the
    /// texture cache's latency). `downstream`: the hit checker.
    ShadingBlock(sc_core::sc_module_name name, const ShadingConfig& config, const ShadingInputs& inputs,
                 RaySinkIf& downstream, MemIf* l2, Cycle interconnect_latency, bool detailed);
    ~ShadingBlock() override;

    void ray_done(const RayResult& result) override;
    void packet_done(const RayResult* results, const Ray* rays, const TraversalMode* modes, uint32_t n) override;

    /// Cycle the primary rays are generated (traversal of the first wavefront starts then).
    Cycle raygen_end() const { return m_raygen_end; }
    /// wavefront: wavefront `w`'s last ray finished at `end`; shades it and returns the cycle its
    /// children may start (the shading's end).
    Cycle wavefront_end(uint32_t w, Cycle end);
    /// wavefront, an animated trace: frame `f`'s primary rays are generated from `at` (its
    /// camera program, after the previous frame's last bounce); returns when its rays may start.
    Cycle begin_frame(uint32_t f, Cycle at);
    /// wavefront, an animated trace: the frame's structures are built until `built` (the build
    /// unit, beside the camera rays' generation); its rays start at neither's end before. Returns
    /// when they may start; the wait beyond the ray generation is the breakdown's `build`.
    Cycle await_build(Cycle built);
    /// inflight, an animated trace: frame f's last ray finished at `end`; shades the hits still
    /// waiting for a warp and returns the cycle the frame's last ray is shaded (the frame's end,
    /// after which the next frame's camera rays are generated: begin_frame, await_build).
    Cycle end_frame_inflight(Cycle end);
    /// inflight: when ray `id`'s parent is shaded, true and *not_before = that cycle.
    bool parent_shaded(uint64_t id, Cycle* not_before) const;
    /// inflight: the ray whose shading ray `id` waits for (its parent).
    uint64_t parent_of(uint64_t id) const;
    /// inflight: the RT unit has no ray in flight (every ray handed out has finished).
    std::function<bool()> rt_idle;
    /// inflight: called with the rays whose warps were shaded (their children may now go).
    std::function<void(const std::vector<uint64_t>& shaded)> on_shaded;

    /// The frame: its time and breakdown, the shader cores', texture caches' and sorting stage's figures.
    nlohmann::json stats_json(Cycle rt_end, double clock_ghz) const;
    Cycle frame_end(Cycle rt_end) const;
    uint64_t texel_mismatches() const { return m_texel_mismatches; }
    uint64_t shaded() const { return m_shaded; }
    /// Rays that started before their parent was shaded, or finished twice (0 allowed).
    uint64_t order_violations() const { return m_order_violations + m_shaded_twice; }
    const std::vector<std::unique_ptr<Cache>>& tex_caches() const { return m_tex; }
    /// The first texel mismatch, for the validation report (empty if none).
    const std::string& first_mismatch() const { return m_first_mismatch; }

private:
    struct Lane {
        uint64_t id;
        Cycle ready;
        LaneProgram program;
        uint32_t key_material;
        uint8_t octant;
        uint32_t texel_offset;  ///< into m_texels
    };
    Lane lane_of(const RayResult& r);
    /// Shades `lanes` (already in warp order) from `ready`; returns the last warp's end.
    Cycle shade(std::vector<Lane>& lanes, Cycle ready, bool sort);
    void run_warps(std::vector<Lane>& lanes, size_t first, size_t end, Cycle ready);
    void flush_inflight(Cycle now);
    /// Generates the primaries among rays [first, first + rays) from cycle `at`; returns the end.
    Cycle raygen(uint64_t first, uint64_t rays, Cycle at);

    const ShadingConfig& m_config;
    const ShadingInputs& m_in;
    RaySinkIf& m_downstream;
    std::vector<std::unique_ptr<Cache>> m_tex;
    std::unique_ptr<ShaderCores> m_cores;
    std::vector<Lane> m_pending;     ///< finished rays not yet shaded
    std::vector<uint64_t> m_texels;  ///< their texel addresses
    std::vector<uint64_t> m_shaded_ids;  ///< inflight: the rays of the last flush
    std::vector<Cycle> m_shaded_at;  ///< per ray: when its warp finished (inflight), 0 before
    std::vector<uint8_t> m_done;     ///< per ray: shaded
    std::vector<uint8_t> m_seen;     ///< per ray: finished (handed to the shading block)
    Cycle m_raygen_end = 0;       ///< the first frame's ray generation
    uint64_t m_raygen_cycles = 0;  ///< every frame's ray generation, summed (the frame accounting)
    Cycle m_reorder_exposed = 0;  ///< sorting before the first warp of the current batch
    // Frame accounting (wavefront: serial parts that sum to the frame time).
    Cycle m_release = 0;  ///< current wavefront's start
    uint64_t m_traversal = 0, m_reorder = 0, m_shading = 0, m_texture_bound = 0, m_build = 0;
    // inflight over frames: each frame's RT span (release to its last ray) and shading tail.
    uint64_t m_frames_ended = 0, m_inflight_rt = 0, m_inflight_tail = 0;
    Cycle m_last_end = 0;
    nlohmann::json m_wavefronts = nlohmann::json::array();
    // Counters.
    uint64_t m_shaded = 0, m_hits = 0, m_misses = 0, m_shadow = 0, m_warps = 0, m_programs = 0;
    uint64_t m_issued = 0, m_lane_instructions = 0, m_lane_slots = 0, m_samples = 0, m_tex_lines = 0;
    uint64_t m_sorted = 0, m_texel_mismatches = 0, m_max_pending = 0;
    uint64_t m_order_violations = 0, m_shaded_twice = 0;
    uint64_t m_raygen_issued = 0, m_raygen_lane_instructions = 0;
    std::string m_first_mismatch;
};

}  // namespace rtsim
