#include "sim/report/technique_cost.h"

#include <cmath>

#include "sim/report/energy_area.h"
#include "rtl_model/traversal/simt/simt_config.h"
#include "rtl_model/traversal/stack_prefetcher.h"
#include "traces/accel/leaf_blocks.h"

namespace rtsim {

using nlohmann::json;

namespace {

// Every figure below is an assumption of ours unless it names a source; docs/energy_area.md
// ("What each technique adds") gives the reasoning for each.

/// A flip-flop bit against an SRAM bit: a latch pair with its clock load against a 6T cell with
/// its share of periphery (standard-cell flip-flops are 4-6x a 6T cell's area; we take 4).
constexpr double kFlopCellFactor = 4.0;
/// A compressed node's child box decodes as p[a] + float(q) x 2^(e[a] - 127) per coordinate
/// (docs/accel.md, Ylitie, Karras & Laine 2017): the u8 to float is a shift into the mantissa
/// and the power of two an exponent add (two integer-adder equivalents), the origin an fp add.
constexpr double kDecodeAdds = 6, kDecodeCmps = 12;
/// A compressed leaf's triangle (Benthin et al. 2018): three byte indices select three vertices
/// of the block buffer (three index adds and three read muxes, six integer-adder equivalents).
constexpr double kLeafCmps = 6;
/// Bytes of one vertex; a triangle test reads three from the block buffer, and each is written
/// once when its block arrives (a vertex shared by several triangles is written once, so this
/// is an upper bound).
constexpr double kVertexBytes = 12;
/// A warp's (or packet's, or MIMD context's) scheduler entry: operation kind, ready bit, age,
/// the warp's node and stack pointer, bytes.
constexpr double kSchedulerEntryBytes = 8;
/// Masks per SIMT warp: the active lanes and the lanes waiting on the other operation kind
/// (while-while keeps both, Aila & Laine 2009).
constexpr double kSimtMasks = 2;
/// A coalescer's address queue: one 8-byte line address per lane.
constexpr double kLaneAddressBytes = 8;
/// A ray in the sorting stage's window: its record (origin, direction, t interval: 32 B), id
/// (4 B) and key (8 B), rounded to 48 bytes.
constexpr double kSortEntryBytes = 48;
/// The treelet prefetcher per stream: treelet, next line, end, bytes (Chou, Nowicki & Aamodt
/// 2023 keep a treelet's lines contiguous, so a footprint is a start and a count carried with
/// the treelet's root: no table SRAM); and its request queue per unit.
constexpr double kPrefetchStreamBytes = 16, kPrefetchQueueEntries = 16, kPrefetchQueueEntryBytes = 8;

/// AQB8-style quantised box tests, per node step: the ray re-expressed in the node's grid (its
/// origin minus the node's origin, 3 fp adds; the scale by 2^-e and the inverse direction's by
/// 2^e are exponent adds, 6 integer adds) before the child boxes' integer tests. The
/// requantiser sits beside each box pipeline lane.
constexpr double kRequantAdds = 3, kRequantCmps = 6;
/// Cooperative lanes (CoopRT, ISCA 2025) per SIMT lane: the lane it helps (an index and a valid
/// bit; a helper writes its hits to the helped ray's state in the warp buffer), the pick (a
/// compare of stack depths) and the merge (a t compare against the helped ray's best).
constexpr double kCoopLaneCmps = 2;
/// Stack-driven prefetching (TTP, Tozlu, Naithani & Zhou 2026): per stream an armed bit; per unit
/// the last StackPrefetcher::kRecent line addresses sent (8 bytes each) and a request queue like
/// the treelet prefetcher's; per line, kRecent address compares.
constexpr double kStackPrefetchLineBytes = 8;

/// The build unit (rtl_model/build_unit, an LBVH-style builder after Viitanen et al. 2017) per
/// triangle a rebuild streams: its box (twelve min/max over three vertices), centroid (three
/// adds; the halving is an exponent decrement), the Morton quantisation against the scene box
/// (three adds, three multiplies; the bit interleave is wiring); and per read pass one key compare
/// in the sort's merge, and its key and index (12 bytes) read and written in the unit's SRAM.
constexpr double kBuildTriAdds = 6, kBuildTriMuls = 3, kBuildTriCmps = 12, kBuildKeyBytes = 12;
/// A refitted node: its box is the union of its two children's (six min/max), staged in the SRAM.
constexpr double kRefitCmps = 6, kRefitNodeBytes = 24;
/// An oriented fit's node in one table frame: a binary tree has about as many nodes as
/// triangles, so one triangle's three vertices rotated (27 multiplies, 18 adds) and boxed (12
/// min/max), the union of the two children (6) and the area compare against the best so far
/// (the half area: 3 multiplies, 2 adds; 1 compare).
constexpr double kFitAdds = 20, kFitMuls = 30, kFitCmps = 19;

bool is_built(const json& list, const char* block) {
    for (const json& b : list)
        if (b.value("block", "") == block) return b.value("instantiated", false);
    return false;
}

double flop_mm2(const EnergyConfig& c, double bytes) { return sram_mm2(c, bytes) * kFlopCellFactor; }

/// Box (or triangle) pipelines' lanes: what the per-test logic next to them is replicated by.
double lanes_of(const SimConfig& s, const PipelineConfig& p) {
    const double pipes = p.sharing == Sharing::shared ? p.shared_count : s.traversal.units;
    return pipes * double(p.width) / double(p.initiation_interval);
}

/// Streams a unit's prefetcher keeps: one per consumer (a treelet queue's, or each ray context
/// or warp lane without queues: rtl_model/traversal/treelet_prefetcher.h).
double prefetch_streams(const SimConfig& s) {
    const TraversalConfig& t = s.traversal;
    return s.treelets.enabled ? double(t.kind().treelet_consumers(t)) : double(t.contexts());
}

/// stats["model"]["units"], or an empty object when the level wrote none (functional: null).
json units_of(const json& stats) {
    const json& model = stats.contains("model") ? stats["model"] : json();
    if (!model.is_object() || !model.contains("units") || !model["units"].is_object()) return json::object();
    return model["units"];
}

/// A counter summed over the units' stats (0 when no unit wrote it).
double unit_sum(const json& stats, const char* key) {
    double sum = 0;
    for (const json& u : units_of(stats))
        if (u.is_object() && u.contains(key) && u[key].is_number()) sum += u[key].get<double>();
    return sum;
}

/// A field of the units' `block` objects (prefetch, stack_prefetch), summed.
double unit_block_sum(const json& stats, const char* block, const char* key) {
    double sum = 0;
    for (const json& u : units_of(stats))
        if (u.is_object() && u.contains(block) && u[block].is_object()) sum += u[block].value(key, 0.0);
    return sum;
}

/// Group steps of a lock-step kind (warp or packet steps), from the units' lane slots.
double group_steps(const SimConfig& s, const json& stats) {
    return unit_sum(stats, "lane_slots") / std::max<double>(1, s.traversal.group_size());
}

double prefetched_lines(const json& stats) { return unit_block_sum(stats, "prefetch", "sent"); }

}  // namespace

json structure_blocks(const std::string& kind, const std::string& blas_kind, bool compressed_leaves) {
    const bool nodes = kind.rfind("cwbvh", 0) == 0 || blas_kind.rfind("cwbvh", 0) == 0;
    const bool oriented = kind.rfind("obvh", 0) == 0 || blas_kind.rfind("obvh", 0) == 0;
    return json::array(
        {{{"block", "node_decoder"}, {"instantiated", nodes},
          {"why", nodes ? "compressed nodes (" + (kind == "two_level" ? blas_kind : kind) +
                              "): each box test dequantises its child box"
                        : std::string("the structure's nodes hold fp32 boxes")}},
         {{"block", "leaf_decoder"}, {"instantiated", compressed_leaves},
          {"why", compressed_leaves ? "compressed leaves: triangles decoded from leaf blocks (Benthin et al. 2018)"
                                    : std::string("triangles stored as plain records")}},
         {{"block", "obb_fit"}, {"instantiated", oriented},
          {"why", oriented ? "oriented nodes: a build or refit on the build unit boxes each node in its fit's frames"
                           : std::string("the structure's boxes are axis-aligned")}}});
}

TechniqueArea technique_area(const SimConfig& s, const json& inst) {
    const EnergyConfig& c = s.energy;
    const TraversalConfig& t = s.traversal;
    TechniqueArea a;
    // An integer box pipeline tests the quantised boxes as stored: no dequantiser, a requantiser.
    if (t.quantized_boxes) a.logic_mm2["ray_requantizer"] = lanes_of(s, s.box) * logic_mm2(c, kRequantAdds, 0, kRequantCmps);
    else if (is_built(inst, "node_decoder"))
        a.logic_mm2["node_decoder"] = lanes_of(s, s.box) * logic_mm2(c, kDecodeAdds, 0, kDecodeCmps);
    if (is_built(inst, "leaf_decoder")) {
        // One block buffer per triangle pipeline, sized for the largest block (the default
        // leaf_block_bytes: the trace's own is not in the config).
        const double pipes = s.triangle.sharing == Sharing::shared ? s.triangle.shared_count : t.units;
        a.sram_bytes["leaf_decoder"] = pipes * double(LeafConfig{}.block_bytes);
        a.logic_mm2["leaf_decoder"] = lanes_of(s, s.triangle) * logic_mm2(c, 0, 0, kLeafCmps);
    }
    const double groups = t.groups(), lanes = t.group_size();
    if (t.model == "simt") {
        // Warp scheduler (an entry and an arbiter input per warp), lane masks, coalescer (a line
        // comparator and an address per lane), per unit.
        const double flops = groups * (kSchedulerEntryBytes + kSimtMasks * lanes / 8) + lanes * kLaneAddressBytes;
        a.logic_mm2["simt_control"] = t.units * (flop_mm2(c, flops) + logic_mm2(c, 0, 0, groups + lanes));
    } else if (t.model == "packet") {
        const double flops = groups * (kSchedulerEntryBytes + lanes / 8);
        a.logic_mm2["packet_control"] = t.units * (flop_mm2(c, flops) + logic_mm2(c, 0, 0, groups));
    } else {
        // MIMD: every ray context is a scheduler entry and an arbiter input.
        a.logic_mm2["context_scheduler"] =
            t.units * (flop_mm2(c, t.contexts() * kSchedulerEntryBytes) + logic_mm2(c, 0, 0, t.contexts()));
    }
    if (s.dispatch.sort != RaySort::none) {
        a.sram_bytes["sort_stage"] = double(s.dispatch.sort_window) * kSortEntryBytes;
        // A merge network: per ray per cycle, log2(window) comparator stages of a 64-bit key.
        const double stages = std::ceil(std::log2(double(std::max<uint32_t>(2, s.dispatch.sort_window))));
        a.logic_mm2["sort_stage"] = logic_mm2(c, 0, 0, 2.0 * stages * s.dispatch.sort_rays_per_cycle);
    }
    if (s.treelets.prefetch && !s.ideal_memory) {
        const double bytes = prefetch_streams(s) * kPrefetchStreamBytes + kPrefetchQueueEntries * kPrefetchQueueEntryBytes;
        a.logic_mm2["prefetcher"] = t.units * (flop_mm2(c, bytes) + logic_mm2(c, 0, 0, 2));  // line address adder, end compare
    }
    if (t.model == "simt" && t.kind_config<SimtConfig>().cooperative) {
        const double index_bits = std::ceil(std::log2(std::max(2.0, lanes))) + 1;
        const double bytes = t.contexts() * index_bits / 8;
        a.logic_mm2["cooperation"] = t.units * (flop_mm2(c, bytes) + logic_mm2(c, 0, 0, kCoopLaneCmps * lanes));
    }
    if (t.stack_prefetch && !s.ideal_memory) {
        const double bytes = t.contexts() / 8.0 + StackPrefetcher::kRecent * kStackPrefetchLineBytes +
                             kPrefetchQueueEntries * kPrefetchQueueEntryBytes;
        a.logic_mm2["stack_prefetcher"] = t.units * (flop_mm2(c, bytes) + logic_mm2(c, 0, 0, double(StackPrefetcher::kRecent)));
    }
    if (is_built(inst, "build_unit")) {
        const BuildUnitConfig& b = s.build_unit;
        a.sram_bytes["build_unit"] = double(b.sram_kib) * 1024.0;
        a.logic_mm2["build_unit"] =
            std::ceil(b.rebuild_triangles_per_cycle) * logic_mm2(c, kBuildTriAdds, kBuildTriMuls, kBuildTriCmps + 1) +
            std::ceil(b.refit_nodes_per_cycle) * logic_mm2(c, 0, 0, kRefitCmps);
        // Its fit datapath for oriented nodes, only where the structure has them.
        if (is_built(inst, "obb_fit"))
            a.logic_mm2["obb_fit"] = std::ceil(b.fit_frames_per_cycle) * logic_mm2(c, kFitAdds, kFitMuls, kFitCmps);
    }
    if (s.mailbox.entries)  // a lookup compares the reference with every entry at once, per unit
        a.logic_mm2["mailbox_compare"] = t.units * logic_mm2(c, 0, 0, s.mailbox.entries);
    return a;
}

std::map<std::string, double> technique_energy_pj(const SimConfig& s, const WorkTotals& w, const json& stats) {
    const EnergyConfig& c = s.energy;
    const TraversalConfig& t = s.traversal;
    const json inst = stats.contains("instantiated") && stats["instantiated"].is_array() ? stats["instantiated"]
                                                                                        : json::array();
    std::map<std::string, double> pj;
    const double box_tests = double(w[work_field_of(OpKind::box)] + w[WorkField::restart_box_tests] +
                                    w[WorkField::rp_box_tests]);
    const double tri_tests = double(w[work_field_of(OpKind::triangle)] + w[WorkField::rp_tri_tests]);
    const double steps = double(w[WorkField::steps] + w[WorkField::rp_steps]);
    if (t.quantized_boxes) pj["ray_requantizer"] = steps * logic_pj(c, kRequantAdds, 0, kRequantCmps);
    else if (is_built(inst, "node_decoder")) pj["node_decoder"] = box_tests * logic_pj(c, kDecodeAdds, 0, kDecodeCmps);
    if (is_built(inst, "leaf_decoder")) {
        const double buffer = double(LeafConfig{}.block_bytes);
        pj["leaf_decoder"] = tri_tests * (logic_pj(c, 0, 0, kLeafCmps) +
                                          2 * sram_access_pj(c, buffer, 3 * kVertexBytes * 8));  // read + written
    }
    const double groups = t.groups(), lanes = t.group_size();
    if (t.model == "simt") {
        // Each warp step: the scheduler's pick over the warps, the masks updated, the coalescer's
        // compares over the lanes.
        pj["simt_control"] = group_steps(s, stats) * logic_pj(c, 0, 0, groups + 2 * lanes);
    } else if (t.model == "packet") {
        pj["packet_control"] = group_steps(s, stats) * logic_pj(c, 0, 0, groups + lanes);
    } else {
        pj["context_scheduler"] = steps * logic_pj(c, 0, 0, t.contexts());
    }
    const json& summary = stats.contains("summary") && stats["summary"].is_object() ? stats["summary"] : json::object();
    const double rays = summary.contains("rays") && summary["rays"].is_number() ? summary["rays"].get<double>() : 0.0;
    if (s.dispatch.sort != RaySort::none) {
        const double stages = std::ceil(std::log2(double(std::max<uint32_t>(2, s.dispatch.sort_window))));
        const double window = double(s.dispatch.sort_window) * kSortEntryBytes;
        pj["sort_stage"] = rays * (2 * sram_access_pj(c, window, kSortEntryBytes * 8) + logic_pj(c, 0, 0, 2 * stages + 3));
    }
    if (s.treelets.prefetch && !s.ideal_memory) {
        const double state = prefetch_streams(s) * kPrefetchStreamBytes;
        pj["prefetcher"] = prefetched_lines(stats) * (2 * sram_access_pj(c, state, kPrefetchStreamBytes * 8) +
                                                      logic_pj(c, 0, 0, 2));
    }
    if (t.model == "simt" && t.kind_config<SimtConfig>().cooperative) {
        // Per helper step: the handed-over stack entry read from the owner's stack and written
        // to the helper's, the pick and the merge compares.
        const double stack = double(t.stack_entries) * t.stack_entry_bytes;
        pj["cooperation"] = unit_sum(stats, "helper_steps") *
                            (2 * sram_access_pj(c, stack, t.stack_entry_bytes * 8.0) + logic_pj(c, 0, 0, kCoopLaneCmps));
    }
    if (t.stack_prefetch && !s.ideal_memory) {
        const double sent = unit_block_sum(stats, "stack_prefetch", "sent") + unit_block_sum(stats, "stack_prefetch", "repeats");
        pj["stack_prefetcher"] = sent * logic_pj(c, 0, 0, double(StackPrefetcher::kRecent));
    }
    const json& model = stats.contains("model") && stats["model"].is_object() ? stats["model"] : json::object();
    if (is_built(inst, "build_unit") && model.contains("build_unit") && model["build_unit"].is_object()) {
        const BuildUnitConfig& b = s.build_unit;
        const double sram = double(b.sram_kib) * 1024.0, passes = double(b.rebuild_read_passes);
        const double triangles = model["build_unit"].value("rebuilt_triangles", 0.0);
        const double nodes = model["build_unit"].value("refit_nodes", 0.0);
        pj["build_unit"] =
            triangles * (logic_pj(c, kBuildTriAdds, kBuildTriMuls, kBuildTriCmps) +
                         passes * (logic_pj(c, 0, 0, 1) + 2 * sram_access_pj(c, sram, kBuildKeyBytes * 8))) +
            nodes * (logic_pj(c, 0, 0, kRefitCmps) + sram_access_pj(c, sram, kRefitNodeBytes * 8));
        const double fit = model["build_unit"].value("fit_node_frames", 0.0);
        if (fit > 0) pj["obb_fit"] = fit * (logic_pj(c, kFitAdds, kFitMuls, kFitCmps) + sram_access_pj(c, sram, kRefitNodeBytes * 8));
    }
    if (s.mailbox.entries) pj["mailbox_compare"] = double(w[WorkField::mailbox_lookups]) * logic_pj(c, 0, 0, s.mailbox.entries);
    return pj;
}

}  // namespace rtsim
