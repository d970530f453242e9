#pragma once
// Configuration of the shading block (docs/shading.md): SIMT shader cores running ray generation
// and hit shading as costed programs, their texture caches, the frame loop, and an optional
// reordering stage before shading.
//
// The cost table is in warp instructions per lane-program; its defaults are first-order counts
// of a glTF metallic-roughness shader (docs/shading.md, "Cost table": a UE4/Filament-style PBR
// BRDF is ~100-150 ALU instructions, a normal map adds the TBN transform, each texture read one
// sample instruction), not measurements of a particular GPU: every entry is a config field.
#include <cstdint>

#include "rtl_model/common/choice.h"
#include "rtl_model/mem/cache_config.h"

namespace rtsim {

/// wavefront: trace a whole bounce, shade it, generate the next (a barrier per bounce);
/// inflight: a warp's children issue as soon as the warp is shaded.
enum class FrameLoop : uint8_t { wavefront = 0, inflight = 1 };
inline constexpr Choices<FrameLoop, 2> kFrameLoopChoices{{"wavefront", "inflight"}};

/// The key hits are regrouped by before warps are formed (NVIDIA SER, Intel's thread sorting unit).
enum class ShadeReorder : uint8_t { none = 0, shader = 1, material = 2, material_direction = 3 };
inline constexpr Choices<ShadeReorder, 4> kShadeReorderChoices{{"none", "shader", "material", "material_direction"}};

/// Instructions per lane of each program part (a hit shader is the sum of its features' parts).
struct ShaderCosts {
    uint32_t raygen = 40;         ///< camera ray generation per primary ray
    uint32_t miss = 20;           ///< miss shader (environment lookup, constant here)
    uint32_t hit_base = 120;      ///< any hit shader: attribute interpolation, PBR BRDF, next-ray setup
    uint32_t base_color_tex = 6;  ///< base colour sample and its use
    uint32_t normal_tex = 24;     ///< normal map: sample, unpack, TBN transform
    uint32_t metal_rough_tex = 6; ///< metallic-roughness sample
    uint32_t emissive_tex = 4;    ///< emissive sample
    uint32_t occlusion_tex = 4;   ///< occlusion sample
    uint32_t alpha_mask = 12;     ///< alpha cutoff and coverage handling
    uint32_t alpha_blend = 16;    ///< blending with what lies behind
    uint32_t transmission = 40;   ///< refraction: Fresnel, refracted direction
    uint32_t metallic = 20;       ///< specular lobe, reflection ray setup
    uint32_t emissive = 4;        ///< emission added
    uint32_t shadow_result = 6;   ///< consuming a shadow ray's answer (light contribution)
    uint32_t sample_issue = 1;    ///< issue slots per texture sample instruction

    template <class V>
    void visit(V& v) {
        v.field("raygen", raygen, "instructions", "Ray generation per primary ray (camera ray setup)", 0, 1u << 20);
        v.field("miss", miss, "instructions", "Miss shader per missing path ray", 0, 1u << 20);
        v.field("hit_base", hit_base, "instructions", "Every hit shader: attribute interpolation, PBR BRDF, next-ray setup", 0, 1u << 20);
        v.field("base_color_tex", base_color_tex, "instructions", "Base colour texture: its sample's use", 0, 1u << 20);
        v.field("normal_tex", normal_tex, "instructions", "Normal map: unpack and TBN transform", 0, 1u << 20);
        v.field("metal_rough_tex", metal_rough_tex, "instructions", "Metallic-roughness texture", 0, 1u << 20);
        v.field("emissive_tex", emissive_tex, "instructions", "Emissive texture", 0, 1u << 20);
        v.field("occlusion_tex", occlusion_tex, "instructions", "Occlusion texture", 0, 1u << 20);
        v.field("alpha_mask", alpha_mask, "instructions", "Alpha MASK materials: cutoff and coverage", 0, 1u << 20);
        v.field("alpha_blend", alpha_blend, "instructions", "Alpha BLEND materials: blending", 0, 1u << 20);
        v.field("transmission", transmission, "instructions", "Transmissive materials: Fresnel and refraction", 0, 1u << 20);
        v.field("metallic", metallic, "instructions", "Metallic or smooth materials: specular lobe", 0, 1u << 20);
        v.field("emissive", emissive, "instructions", "Emissive materials: emission", 0, 1u << 20);
        v.field("shadow_result", shadow_result, "instructions", "Per shadow ray: its answer used by the parent's shader", 0, 1u << 20);
        v.field("sample_issue", sample_issue, "instructions", "Issue slots per texture sample instruction", 0, 1024);
    }
};

struct ShadingConfig {
    bool enabled = false;          ///< model the frame: shading, ray generation and the frame loop
    FrameLoop frame_loop = FrameLoop::wavefront;
    uint32_t cores = 8;            ///< SIMT shader cores
    uint32_t warp_width = 32;      ///< lanes per warp
    uint32_t issue_per_cycle = 1;  ///< warp instructions issued per core per cycle
    uint32_t warps_resident = 32;  ///< warps a core keeps in flight (hides texture latency)
    uint32_t tex_latency = 8;      ///< cycles of texture filtering after the texels arrive
    uint32_t form_timeout = 2000;  ///< inflight: cycles a partial warp waits for more hits
    ShadeReorder reorder = ShadeReorder::none;
    uint32_t reorder_window = 4096;      ///< hits the sorting stage groups together
    uint32_t reorder_rays_per_cycle = 8; ///< sorting stage throughput
    uint32_t reorder_latency = 100;      ///< cycles from a window's last hit in to its first warp out
    uint32_t reorder_entry_bytes = 16;   ///< buffer SRAM per hit (ray id, key)
    double alu_pj = 2.0;           ///< energy per lane instruction (pJ)
    double tex_sample_pj = 10.0;   ///< energy per texture sample's filtering (pJ), cache access aside
    double reorder_pj = 4.0;       ///< energy per hit through the sorting stage (pJ)
    double core_mm2 = 2.0;         ///< area per shader core (mm^2 at the energy model's node)
    ShaderCosts cost;
    /// Each core's texture cache (misses go to the shared L2).
    CacheConfig tex_cache = [] {
        CacheConfig c;
        c.size_kib = 32;
        c.ways = 8;
        c.latency = 20;
        c.mshrs = 64;
        return c;
    }();

    template <class V>
    void visit(V& v) {
        v.flag("enabled", enabled, "Model the whole frame: ray generation and hit shading on SIMT shader cores, the frame loop (needs a trace with shading sections, version 5)");
        v.choice("frame_loop", frame_loop, kFrameLoopChoices, "wavefront: trace a bounce, shade it, generate the next; inflight: a warp's children issue as soon as it is shaded");
        v.field("cores", cores, "cores", "SIMT shader cores", 1, 4096);
        v.field("warp_width", warp_width, "lanes", "Lanes per warp", 1, 128);
        v.field("issue_per_cycle", issue_per_cycle, "instructions/cycle", "Warp instructions each core issues per cycle", 1, 16);
        v.field("warps_resident", warps_resident, "warps", "Warps a core keeps in flight to hide texture latency", 1, 1024);
        v.field("tex_latency", tex_latency, "cycles", "Texture filtering after the texels arrive", 0, 10000);
        v.field("form_timeout", form_timeout, "cycles", "inflight: cycles a partial warp waits for more hits before it is shaded", 1, 1u << 24);
        v.choice("reorder", reorder, kShadeReorderChoices, "Regroup hits before warps are formed: none, shader (hit shader id), material, material_direction (material, then direction octant)");
        v.field("reorder_window", reorder_window, "rays", "Hits the sorting stage groups together", 2, 1u << 20);
        v.field("reorder_rays_per_cycle", reorder_rays_per_cycle, "rays/cycle", "Sorting stage throughput", 1, 1024);
        v.field("reorder_latency", reorder_latency, "cycles", "Sorting stage latency (a window's last hit in to its first warp out)", 0, 1u << 20);
        v.field("reorder_entry_bytes", reorder_entry_bytes, "bytes", "Sorting buffer SRAM per hit (ray id and key)", 1, 1024);
        v.field("alu_pj", alu_pj, "pJ", "Energy per lane instruction", 0.0, 1e6);
        v.field("tex_sample_pj", tex_sample_pj, "pJ", "Energy per texture sample (filtering; the cache access is counted by the cache)", 0.0, 1e6);
        v.field("reorder_pj", reorder_pj, "pJ", "Energy per hit through the sorting stage", 0.0, 1e6);
        v.field("core_mm2", core_mm2, "mm^2", "Area per shader core", 0.0, 1e6);
        v.section("cost", cost);
        v.section("tex_cache", tex_cache);
    }
};

}  // namespace rtsim
