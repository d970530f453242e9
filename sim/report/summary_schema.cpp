// The summary keys (summary_schema.h). Add a key here first; docs/stats.md follows from it.
#include "sim/report/summary_schema.h"

#include <string>

#include "traces/common/error.h"

namespace rtsim {

const StatBlock& summary_stats() {
    static const StatBlock block{"summary", {
        {"rays", "rays",
         "rays in the trace, all simulated",
         false, false},
        {"fidelity", "",
         "the level that ran (as the top-level `fidelity`)",
         false, false},
        {"cycles", "cycles",
         "cycle the last ray's hit was written (max over units' `finish_cycle`); `null` at functional",
         true, false},
        {"seconds", "s",
         "`cycles / (clock_ghz * 1e9)`; `null` at functional",
         true, false},
        {"rays_per_second", "rays/s",
         "`rays / seconds`: the simulated chip's throughput; `null` at functional",
         true, false},
        {"mrays_per_second", "Mrays/s",
         "the same in millions",
         true, false},
        {"avg_ray_latency_cycles", "cycles",
         "mean of `latency` (ray assigned to a context to hit written)",
         true, false},
        {"hit_mismatches", "rays",
         "rays whose hit (primitive id or the bits of t) differ from the reference; must be 0",
         false, false},
        {"work_mismatches", "rays",
         "rays with the same hit but different node/box/triangle/alpha-test counts",
         false, false},
        {"wall_seconds", "s",
         "host wall time of the whole run (reading, simulating, writing)",
         false, false},
        {"simulated_rays_per_wall_second", "rays/s",
         "simulator speed: `rays / wall_seconds`",
         false, false},
        {"peak_memory_mib", "MiB",
         "peak resident memory of the rtsim-sim process (VmHWM); stays flat as traces grow, since rays are streamed in chunks",
         false, false},
        {"unit_busy_fraction", "fraction",
         "mean over units of `model.units.<unit>.busy_fraction`",
         true, false},
        {"simd_efficiency", "fraction",
         "unit kinds that step groups in lock-step (simt, packet): active lanes / lane slots over every unit's warp (or packet) steps (`model.units.<unit>.simd_efficiency`, Aila & Laine 2009)",
         false, true},
        {"box_utilization", "fraction",
         "mean over box pipeline blocks of `utilization`",
         true, false},
        {"triangle_utilization", "fraction",
         "mean over triangle pipeline blocks of `utilization`",
         true, false},
        {"l1_hit_rate", "fraction",
         "over all L1s: (read_hits + merged) / reads; `null` with `ideal_memory`",
         true, false},
        {"l2_hit_rate", "fraction",
         "the L2's (read_hits + merged) / reads; `null` with `ideal_memory`",
         true, false},
        {"dram_bytes", "bytes",
         "DRAM read + write bytes (0 with `ideal_memory`)",
         true, false},
        {"dram_bytes_per_ray", "bytes/ray",
         "`dram_bytes / rays`",
         true, false},
        {"dram_bandwidth_gbps", "GB/s",
         "`model.dram.bandwidth_gbps`: average over the whole run",
         true, false},
        {"dram_bandwidth_utilization", "fraction",
         "achieved over peak DRAM bandwidth",
         true, false},
        {"frames", "frames",
         "frames replayed in sequence with caches warm (an animated trace, `rtsim trace --frames N`; 1 otherwise); each frame's figures are in stats.json `frames` ([stats.md](stats.md#frames))",
         false, false},
        {"sampled", "bool",
         "true when only a sample of the rays was simulated ([fidelity.md](fidelity.md#sampling))",
         false, false},
        {"sampling_note", "",
         "timed runs that asked for sampling but were not sampled: why (the sample would cover the whole trace, or no sample fits it); every ray was simulated and the figures are exact. `rtsim-sim` also prints it",
         false, true},
        {"resolved", "",
         "what the run's resolution step settled ([capabilities.md](capabilities.md)): `derived`, the fields the config left to the run (`[{key, value, why}]`: `traversal.ray_contexts` 0 follows the unit kind's warps or packets, `traversal.stack_entry_bytes` 0 the structure's), and `unused`, settings that have no effect on this run (`[{key, why}]`)",
         false, false},
        {"cycles_ci95", "cycles",
         "sampled runs only: `[lo, hi]`, the 95% confidence interval of `cycles`",
         false, true},
        {"rays_per_second_ci95", "rays/s",
         "sampled runs only: `[lo, hi]`, the same interval for `rays_per_second`",
         false, true},
        {"mailbox_hits_per_ray", "tests/ray",
         "triangle tests (and 48-byte triangle fetches) the mailbox skipped per ray (stats.json `mailbox`, [accel.md](accel.md#mailboxes)); `null` without one (`mailbox.entries = 0`)",
         false, false},
        {"energy_per_ray_nj", "nJ/ray",
         "`energy.per_ray_nj.total`: dynamic energy of every block plus leakage, per ray ([energy_area.md](energy_area.md)); `null` at functional",
         true, false},
        {"mrays_per_joule", "Mrays/J",
         "`1e3 / energy_per_ray_nj`: rays per joule, in millions; `null` at functional",
         true, false},
        {"power_w", "W",
         "`energy_per_ray_nj x rays_per_second`: the average power that implies; `null` at functional",
         true, false},
        {"area_mm2", "mm^2",
         "`area.total_mm2`: SRAM plus pipelines at `energy.node_nm`; every level",
         false, false},
        {"bottleneck", "",
         "`verdict.binding`: the resource the verdict names (`dram`, `l2_mshrs`, `pipe_box`, ...); `null` without a verdict",
         true, false},
        {"verdict", "",
         "`verdict.text`: one sentence, printed by `rtsim simulate`",
         true, false},
        {"frame_ms", "ms",
         "only with `shading.enabled`: `model.shading.frame_ms`, the frame from ray generation to the last ray shaded (docs/shading.md)",
         false, true},
        {"shading_share", "fraction",
         "only with `shading.enabled`: the frame's share not in traversal (`model.shading.shading_share`)",
         false, true},
        {"frame_speedup_2x_rt", "x",
         "only with `shading.enabled`: what a 2x faster RT unit buys the frame (`model.shading.amdahl.speedup_2x_rt`)",
         false, true},
        {"shading_divergence", "programs/warp",
         "only with `shading.enabled`: `model.shading.divergence`",
         false, true},
        {"shading_simd_efficiency", "fraction",
         "only with `shading.enabled`: `model.shading.simd_efficiency`",
         false, true},
        {"tex_hit_rate", "fraction",
         "only with `shading.enabled` and a texture model: `model.shading.tex_hit_rate`",
         false, true},
        {"energy_per_frame_mj", "mJ",
         "only with `shading.enabled`: `energy_per_ray_nj x rays` plus the shader cores' `model.shading.energy_pj`",
         false, true},
        {"study_warnings", "list",
         "`study_size.findings[].text`: why the run is too small to answer its question (a ray buffer that never filled, a drain that dominates, a sample too short), each with the trace size that would do; empty when none applies. `rtsim simulate` prints them and the sweep report lists them",
         false, false},
        {"fidelity_warnings", "list",
         "`fidelity_band.findings[].text`: the design is of a kind the level was measured outside its band on (analytic with treelets, or with few rays per context), with the section of docs/fidelity.md that measured it; empty when none applies. `rtsim simulate` prints them and the sweep report lists them",
         false, false},
    }};
    return block;
}

const StatBlock& run_stats() {
    static const StatBlock block{
        "stats.json",
        {
            {"schema", "", "format tag, `\"rtsim-stats/1\"`; bumped when a key changes meaning"},
            {"fidelity", "", "the level that ran: `functional` (counts only), `analytic` (statistical or functional caches + closed form), `approx` (timed SystemC model) or `detailed` (approx + per-cycle arbitration, L2 MSHRs); see [fidelity.md](fidelity.md)"},
            {"summary", "", "the headline numbers (below); what `rtsim simulate` prints and sweeps tabulate"},
            {"validation", "", "the hit check against the reference tracer"},
            {"latency", "", "per-ray latency distribution"},
            {"workload", "", "what the trace asked for"},
            {"instantiated", "list", "which optional blocks the model built, and why"},
            {"effects", "list", "the effects the trace simulates and why (copied from the trace's `manifest.json`)"},
            {"model", "", "every block's own counters, keyed by SystemC instance name (`{}` at functional)"},
            {"provenance", "", "version, git hash, command line, host, trace"},
            {"sampling", "", "only in sampled runs (`sampling.fraction` or `sampling.count`): the sample and the estimate (below)", false, true},
            {"energy", "", "energy per ray by block, power, Mrays/J from the first-order model of [energy_area.md](energy_area.md) (below)"},
            {"area", "", "chip area by block, mm^2, from the same model (below)"},
            {"verdict", "", "why the run is slow: the binding resource, its evidence and the knob that relaxes it (below); `null` at functional or with `--no-verdict`"},
            {"roofline", "", "the run against its throughput ceilings (below); `null` at functional"},
            {"study_size", "", "whether the run is big enough to answer its question, and the trace size that would be (below)"},
            {"fidelity_band", "", "whether the design is of a kind the run's level was measured outside its band on (below)"},
            {"mailbox", "", "only when `mailbox.entries > 0`: the mailboxes' lookups, hits and the triangle tests and fetches they saved (below)", false, true},
            {"short_stack", "", "only when `traversal.stack_overflow = restart_trail`: entries dropped, restarts and the re-traversal they cost (below)", false, true},
            {"box_precision", "", "only when `traversal.box_precision_bits > 0`: the reduced-precision box pipeline's extra walk, its energy and area beside fp32's (below)", false, true},
            {"two_level", "", "only for two-level traces, at the levels that step every ray: the TLAS's and the BLASes' steps and box tests (below)", false, true},
            {"frames", "list", "one entry per frame of the trace (below): a single entry for a trace without frames; absent at the analytic level (it does not replay frames)", false, true},
        }};
    return block;
}

const StatBlock& provenance_stats() {
    static const StatBlock block{
        "provenance",
        {
            {"rtsim_version", "", "rtsim version (top-level `CMakeLists.txt`)"},
            {"git", "", "git hash of the build (`RTSIM_GIT_HASH`)"},
            {"command_line", "", "the `rtsim-sim` command line, as run"},
            {"host", "", "host name"},
            {"started_utc", "", "when the run's stats were written (UTC, ISO 8601)"},
            {"trace", "", "path of the `trace.rtt` simulated"},
            {"scene", "", "scene name from the trace manifest"},
            {"trace_git", "", "git hash of the tracer that wrote the trace (from the manifest)"},
        }};
    return block;
}

/// The summary's optional keys are a sampled run's estimate, except the one a traversal unit kind
/// writes (simd_efficiency: runs of SIMT units only) and the frame's (runs with shading.enabled,
/// which are never sampled).
static bool sampled_only(const StatDecl& d) {
    static const char* const not_sampled[] = {"simd_efficiency", "frame_ms", "shading_share", "frame_speedup_2x_rt",
                                              "shading_divergence", "shading_simd_efficiency", "tex_hit_rate",
                                              "energy_per_frame_mj", "sampling_note"};
    for (const char* k : not_sampled)
        if (std::string(d.key) == k) return false;
    return d.optional;
}

void check_summary(const nlohmann::json& summary, bool sampled) {
    summary_stats().check(summary);
    for (const StatDecl& d : summary_stats().stats)
        require(!sampled_only(d) || !sampled || summary.contains(d.key),
                std::string("stats: 'summary.") + d.key + "' is declared for sampled runs but was not written");
}

RTSIM_REGISTER_STAT_BLOCK(summary_stats)
RTSIM_REGISTER_STAT_BLOCK(run_stats)
RTSIM_REGISTER_STAT_BLOCK(provenance_stats)

}  // namespace rtsim
