#include "sim/report/energy_area.h"
#include "sim/report/report_block.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "rtl_model/mem/mem_stats.h"
#include "rtl_model/ray_buffer/ray_buffer.h"
#include "sim/report/technique_cost.h"

namespace rtsim {

using nlohmann::json;

namespace {

// ---- Technology scaling: Stillmaker & Baas 2017, "Scaling equations for the accurate prediction
// of CMOS device performance from 180 nm to 7 nm", Integration 58:74-81. Energy: their per-node
// polynomial in the supply voltage, a*V^2 + b*V + c (Table 5 coefficients), normalised to 45 nm at
// 1.0 V; area: their area factors relative to 45 nm (Table 3). Nominal voltages are typical values
// for each node (our assumption, docs/energy_area.md); energy.vdd overrides them.
struct Node {
    double nm, a, b, c, area_vs_45, nominal_vdd;
};
constexpr std::array<Node, 10> kNodes{{
    {130, 7.171, -6.709, 2.904, 6.4, 1.3},
    {90, 4.762, -4.781, 2.092, 2.8, 1.2},
    {65, 3.755, -4.398, 1.975, 1.5, 1.1},
    {45, 1.103, -0.362, 0.2767, 1.0, 1.0},
    {32, 0.9559, -0.7823, 0.471, 0.46, 0.9},
    {20, 0.373, -0.1582, 0.04104, 0.21, 0.9},
    {16, 0.2958, -0.1241, 0.03024, 0.19, 0.8},
    {14, 0.2363, -0.09675, 0.02239, 0.17, 0.8},
    {10, 0.2068, -0.09311, 0.02375, 0.1, 0.75},
    {7, 0.1776, -0.09097, 0.02447, 0.059, 0.7},
}};

double poly(const Node& n, double v) { return n.a * v * v + n.b * v + n.c; }

/// Interpolates f(node) linearly in log(nm) between the two table nodes around `nm`.
template <class F>
double across_nodes(double nm, F f) {
    nm = std::clamp(nm, kNodes.back().nm, kNodes.front().nm);
    for (size_t i = 0; i + 1 < kNodes.size(); ++i) {
        const Node& big = kNodes[i];
        const Node& small = kNodes[i + 1];
        if (nm <= big.nm && nm >= small.nm) {
            const double w = std::log(big.nm / nm) / std::log(big.nm / small.nm);
            return (1 - w) * f(big) + w * f(small);
        }
    }
    return f(kNodes.back());
}

// ---- Floating-point operations per test of our arithmetic (docs/energy_area.md, "Operations").
// A fixed-function pipeline evaluates every stage of every test, so each is priced on its full path.
struct Flops {
    double add, mul, cmp, div;
};
// traces/isect/ray_box_kernel.h (Ize 2013 slab test), per child box: per axis 2 sub + 2 mul +
// 1 max + 1 min; then far >= 0, the far scale (1 mul), min with tmax and tnear <= tfar.
constexpr Flops kBoxFlops{6, 7, 9, 0};
// traces/isect/ray_triangle_kernel.h (Woop, Benthin & Wald 2013), hit path: 9 sub (vertices minus
// origin), shear 6 mul + 6 sub, edge functions 6 mul + 3 sub, 6 sign compares, det 2 add, det == 0,
// scaled z 3 mul, t 3 mul + 2 add, sign fold, interval 2 mul + 2 cmp, t / det and u, v / det
// (3 div), t re-check 2 cmp.
constexpr Flops kTriangleFlops{22, 20, 12, 3};
// Alpha test: interpolate the texture coordinate from the barycentrics (w = 1 - u - v: 2 add;
// 2 x (3 mul + 2 add)), compare with the cutoff. The texture fetch is not modelled.
constexpr Flops kAnyhitFlops{6, 6, 1, 0};
// Instance transform: a 3x4 affine map of the origin (9 mul + 9 add) and a 3x3 of the direction
// (9 mul + 6 add), then the ray's precomputation again (as kRaySetupFlops).
constexpr Flops kTransformFlops{15, 20, 2, 4};
// Grid step (Amanatides & Woo 1987): the smallest of three tMax (2 cmp), tMax += tDelta, exit test.
constexpr Flops kCellFlops{1, 0, 3, 0};
// Split-plane test (kd-tree, BIH): (plane - origin) * inv_dir, compared with tmin and tmax.
constexpr Flops kPlaneFlops{1, 1, 2, 0};
/// Per operation kind (OpKind order).
// Oriented node (obvh2): a 3x3 rotation of the origin and the direction (18 mul + 12 add) and
// the three reciprocals of the rotated direction the box tests need.
constexpr Flops kObbFlops{12, 18, 0, 3};
// Ray/sphere (traces/isect/ray_sphere_kernel.h, Haines et al. 2019): origin minus centre 3 sub,
// d.d and f.d 6 mul + 4 add, the closest-approach vector 3 mul + 3 add and its square 3 mul + 2
// add, r^2 - |l|^2 1 mul + 1 sub, the root's argument 1 mul, q 1 add, c 3 mul + 3 add, sign and
// interval 5 cmp; the division b/a, the square root and c/q, q/a priced as 4 divides. The
// reference computes in double; priced here as the fp32 unit hardware would build.
constexpr Flops kSphereFlops{17, 17, 5, 4};
// Ray/capsule (traces/isect/ray_capsule_kernel.h): the axis and its length (3 sub, 3 mul + 2 add,
// a root and a divide for the unit axis), the ray's parts across it (2 x (3 mul + 2 add, 3 mul +
// 3 sub)), then three of the sphere's quadrics (the cylinder's and the two caps') with their
// axial checks (2 x (2 mul + 1 add) and 2 compares each), and the nearest of six crossings (6
// compares). The pipeline tests capsules of two radii too (a round cone), which adds the slope
// k = (r1 - r0) / L and 1 - k^2 (1 sub, 1 mul + 1 sub, a divide), the cone's terms in the body's
// quadric (8 mul + 3 add), its circles of contact (2 mul + 1 sub), and the ray's origin moved to
// the segment's midpoint (6 mul + 5 add, a divide).
constexpr Flops kCapsuleFlops{3 * 17 + 17 + 11, 3 * 17 + 24 + 17, 3 * 5 + 12, 3 * 4 + 2 + 2};
constexpr std::array<Flops, kOpKindCount> kTestFlops{kBoxFlops,  kTriangleFlops, kAnyhitFlops,
                                                     kTransformFlops, kCellFlops, kPlaneFlops,
                                                     kObbFlops,  kSphereFlops,   kCapsuleFlops};
// Per ray: inv_dir (3 div) for the box test; the triangle test's shear constants (RayTrianglePre:
// the largest axis, 2 cmp; 1 / dir_kz, 1 div; sx, sy, 2 mul).
constexpr Flops kRaySetupFlops{0, 2, 2, 4};
/// A divide priced as 4 multiplies: a reciprocal by table plus Newton-Raphson steps (our
/// assumption; Horowitz 2014 lists no divider).
constexpr double kDivInMuls = 4.0;
/// Bytes of a ray context's state read per traversal step (origin, inverse direction, t interval).
constexpr double kContextReadBytes = 32;
/// Bytes of a ray context's state in the unit (ray, inverse direction, hit so far, id): its SRAM.
constexpr double kContextStateBytes = 64;

double flops_pj(const EnergyConfig& c, const Flops& f) {
    return (f.add * c.fp_add_pj + (f.mul + kDivInMuls * f.div) * c.fp_mul_pj + f.cmp * c.cmp_pj) * c.datapath_overhead;
}
double flops_um2(const EnergyConfig& c, const Flops& f) {
    return (f.add * c.fp_add_um2 + (f.mul + kDivInMuls * f.div) * c.fp_mul_um2 + f.cmp * c.cmp_um2) *
           c.datapath_overhead;
}

/// A test's operations on a reduced-precision datapath, counted in fp32 equivalents: `bits`
/// explicit mantissa bits (0: fp32, unchanged). An adder's or comparator's area and energy grow
/// about linearly with its word width (sign, 8 exponent bits, the fraction: 32 for fp32), a
/// multiplier's with its significand width squared (the partial-product array; 24 for fp32);
/// Keely 2014 builds the box tests this way. Our first-order assumption (docs/energy_area.md).
Flops at_precision(const Flops& f, uint32_t bits) {
    if (bits == 0) return f;
    const double word = (bits + 9.0) / 32.0, sig = (bits + 1.0) / 24.0;
    return {f.add * word, f.mul * sig * sig, f.cmp * word, f.div * sig * sig};
}

/// One box test on an AQB8-style integer pipeline (Huang, Yang & Yeh, ISCA 2025), in fp32
/// equivalents: per axis 2 subtracts of 9-bit integers (a child's 8-bit coordinate minus the
/// ray's quantised origin) and 2 multiplies of 9 by 16 bits (the fixed-point inverse direction),
/// then the slab compares at 16 bits. Integer adders and comparators as `cmp` (a 32-bit integer
/// add) scaled by width / 32; a multiplier as fp32's scaled by its partial-product array
/// (9 x 16 against 24 x 24). Our assumption, not the paper's figures (docs/energy_area.md).
constexpr double kQuantAddWidth = 9.0 / 32.0, kQuantMulArray = 9.0 * 16.0 / (24.0 * 24.0), kQuantCmpWidth = 16.0 / 32.0;
constexpr Flops kQuantizedBoxFlops{0, 6 * kQuantMulArray, 6 * kQuantAddWidth + 9 * kQuantCmpWidth, 0};

/// The arithmetic of one box test on the pipeline the config builds.
Flops box_flops(const SimConfig& s) {
    if (s.traversal.quantized_boxes) return kQuantizedBoxFlops;
    return at_precision(kBoxFlops, s.traversal.box_precision_bits);
}

/// A block's stat by its declared key (`block`), 0 when the level wrote null.
double num(const StatBlock& block, const json& j, const char* key) {
    const json& v = StatsReader(block, j)[key];
    return v.is_number() ? v.get<double>() : 0.0;
}

/// Energy of one cache's activity, pJ: reads of a whole line, fills of missed lines, writes of
/// their bytes; tag bits ride along on every access.
double cache_pj(const EnergyConfig& c, const StatBlock& block, const json& cache, double size_bytes,
                double line_bytes) {
    const double reads = num(block, cache, "reads");
    const double misses = std::max(0.0, reads - num(block, cache, "read_hits") - num(block, cache, "merged"));
    const double bits = (reads + misses) * line_bytes * 8 + num(block, cache, "write_bytes") * 8;
    return sram_access_pj(c, size_bytes, bits * (1 + c.sram_tag_overhead));
}

json per_ray(double pj, uint64_t rays) { return rays ? json(pj / 1000.0 / double(rays)) : json(nullptr); }

/// Area of the pipelines behind one operation kind, mm^2: lanes (width / initiation interval, so
/// a pipeline issuing every other cycle can share its units) x the arithmetic of one test.
double pipeline_mm2(const EnergyConfig& c, const SimConfig& s, const PipelineConfig& p, const Flops& f) {
    const double pipes = p.sharing == Sharing::shared ? p.shared_count : s.traversal.units;
    const double lanes = double(p.width) / double(p.initiation_interval);
    return pipes * lanes * flops_um2(c, f) * 1e-6 * area_scale(c);
}

/// The mailboxes' SRAM, bytes: one table of mailbox.entries primitive ids per ray context.
double mailbox_bytes(const SimConfig& s) {
    return double(s.traversal.units) * s.traversal.contexts() * s.mailbox.entries * MailboxConfig::kEntryBytes;
}

bool instantiated(const json& list, const char* block) {
    for (const json& b : list)
        if (b.value("block", "") == block) return b.value("instantiated", false);
    return false;
}

json area_json(const SimConfig& s, const json& stats) {
    const EnergyConfig& c = s.energy;
    const TraversalConfig& t = s.traversal;
    const double tags = 1 + c.sram_tag_overhead;
    // The on-chip SRAM by block, bytes (data only; the caches' tags cost area below).
    json bytes = json::object();
    bytes["l1"] = s.ideal_memory ? 0.0 : double(t.units) * s.l1.size_kib * 1024;
    bytes["l2"] = s.ideal_memory ? 0.0 : double(s.l2.size_kib) * 1024;
    bytes["ray_buffer"] = s.treelets.enabled ? double(s.treelets.buffer_kib) * 1024 : 0.0;
    bytes["stacks"] = double(t.units) * t.contexts() * t.stack_entries * t.stack_entry_bytes;
    bytes["ray_contexts"] = double(t.units) * t.contexts() * kContextStateBytes;
    if (s.mailbox.entries) bytes["mailbox"] = mailbox_bytes(s);
    // What each technique adds (technique_cost.h): its SRAM here, its logic below.
    const TechniqueArea added = technique_area(s, stats.value("instantiated", json::array()));
    for (const auto& [block, b] : added.sram_bytes) bytes[block] = b;
    json mm2 = json::object();
    double sram = 0, sram_bytes = 0;
    for (auto it = bytes.begin(); it != bytes.end(); ++it) {
        const bool cache = it.key() == "l1" || it.key() == "l2";
        mm2[it.key()] = sram_mm2(c, it->get<double>()) * (cache ? tags : 1.0);
        sram += mm2[it.key()].get<double>();
        sram_bytes += it->get<double>();
    }
    mm2["box"] = pipeline_mm2(c, s, s.box, box_flops(s));
    mm2["triangle"] = pipeline_mm2(c, s, s.triangle, kTriangleFlops);
    mm2["anyhit"] = instantiated(stats.value("instantiated", json::array()), "anyhit")
                        ? pipeline_mm2(c, s, s.anyhit, kAnyhitFlops)
                        : 0.0;
    // Blocks only some structures or configs have are listed only when built.
    if (instantiated(stats.value("instantiated", json::array()), "plane"))
        mm2["plane"] = pipeline_mm2(c, s, s.plane, kPlaneFlops);
    if (instantiated(stats.value("instantiated", json::array()), "obb"))
        mm2["obb"] = pipeline_mm2(c, s, s.obb, kObbFlops);
    if (instantiated(stats.value("instantiated", json::array()), "sphere"))
        mm2["sphere"] = pipeline_mm2(c, s, s.sphere, kSphereFlops);
    if (instantiated(stats.value("instantiated", json::array()), "capsule"))
        mm2["capsule"] = pipeline_mm2(c, s, s.capsule, kCapsuleFlops);
    for (const auto& [block, logic] : added.logic_mm2) mm2[block] = mm2.value(block, 0.0) + logic;
    double total = 0;
    for (auto it = mm2.begin(); it != mm2.end(); ++it) total += it->get<double>();
    return {{"mm2", mm2},        {"total_mm2", total},          {"sram_mm2", sram},
            {"logic_mm2", total - sram}, {"sram_bytes", bytes}, {"sram_total_bytes", sram_bytes}};
}

}  // namespace

double logic_mm2(const EnergyConfig& c, double adds, double muls, double cmps) {
    return flops_um2(c, {adds, muls, cmps, 0}) * 1e-6 * area_scale(c);
}

double logic_pj(const EnergyConfig& c, double adds, double muls, double cmps) {
    return flops_pj(c, {adds, muls, cmps, 0}) * energy_scale(c);
}

BoxPipelineCost box_pipeline_cost(const SimConfig& config, bool fp32) {
    const Flops f = fp32 ? kBoxFlops : box_flops(config);
    return {flops_pj(config.energy, f) * energy_scale(config.energy), pipeline_mm2(config.energy, config, config.box, f)};
}

double area_total_mm2(const SimConfig& config, const json& instantiated) {
    return area_json(config, json{{"instantiated", instantiated}})["total_mm2"].get<double>();
}

double supply_voltage(const EnergyConfig& c) {
    return c.vdd > 0 ? c.vdd : across_nodes(c.node_nm, [](const Node& n) { return n.nominal_vdd; });
}

double energy_scale(const EnergyConfig& c) {
    const double v = supply_voltage(c);
    return across_nodes(c.node_nm, [v](const Node& n) { return poly(n, v); }) / poly(kNodes[3], 1.0);
}

double area_scale(const EnergyConfig& c) {
    return across_nodes(c.node_nm, [](const Node& n) { return n.area_vs_45; });
}

double dram_pj_per_bit(const EnergyConfig& c) {
    if (c.dram_pj_per_bit > 0) return c.dram_pj_per_bit;
    switch (c.dram_kind) {
        case DramKind::gddr6: return 7.5;   // Micron GDDR6 device figure (docs/energy_area.md)
        case DramKind::lpddr5: return 5.0;  // assumed from LPDDR4 figures less ~30% (docs/energy_area.md)
        case DramKind::hbm2: return 3.9;    // O'Connor et al., MICRO 2017
        case DramKind::ddr4: return 13.0;   // Horowitz 2014's 1.3 nJ / 64 bit at (1.2 / 1.5 V)^2
    }
    return 0;
}

OpEnergies op_energies(const EnergyConfig& c) {
    const double s = energy_scale(c);
    OpEnergies e;
    for (int k = 0; k < kOpKindCount; ++k) e.test[size_t(k)] = flops_pj(c, kTestFlops[size_t(k)]) * s;
    e.ray_setup = flops_pj(c, kRaySetupFlops) * s;
    return e;
}

double sram_access_pj(const EnergyConfig& c, double bytes, double bits) {
    // Horowitz's 45 nm points (64-bit reads: 8 KiB 10 pJ, 32 KiB 20 pJ, 1 MiB 100 pJ) follow
    // size^0.46-0.5; below 1 KiB the fit is held (small arrays are dominated by their periphery).
    const double size = std::max(bytes, 1024.0) / 8192.0;
    return c.sram_pj_64b * (bits / 64.0) * std::pow(size, c.sram_size_exponent) * energy_scale(c);
}

double sram_mm2(const EnergyConfig& c, double bytes) {
    return bytes / double(1 << 20) * c.sram_mm2_per_mib * area_scale(c);
}

void add_energy_area(json& stats, const SimConfig& s, const WorkTotals& w, uint64_t rays) {
    const EnergyConfig& c = s.energy;
    OpEnergies op = op_energies(c);
    op.test[size_t(OpKind::box)] = box_pipeline_cost(s).test_pj;
    const json& model = stats.value("model", json::object());
    json& summary = stats["summary"];
    const TraversalConfig& t = s.traversal;
    const double line = s.l1.line_bytes;

    // Dynamic energy by block, pJ; null where this level has no counts.
    json pj = json::object();
    for (int k = 0; k < kOpKindCount; ++k)
        pj[op_kind_name(OpKind(k))] = double(w[work_field_of(OpKind(k))]) * op[OpKind(k)];
    // A short stack's restarts re-test the boxes of the nodes they revisit; a reduced-precision
    // box pipeline's extra walk tests boxes and triangles (accel/rp_boxes.h).
    if (w[WorkField::restart_box_tests] || w[WorkField::rp_box_tests])
        pj["box"] = pj["box"].get<double>() +
                    double(w[WorkField::restart_box_tests] + w[WorkField::rp_box_tests]) * op[OpKind::box];
    if (w[WorkField::rp_tri_tests])
        pj["triangle"] = pj["triangle"].get<double>() + double(w[WorkField::rp_tri_tests]) * op[OpKind::triangle];
    if (s.mailbox.entries) {
        // A lookup compares the reference with the ray's whole table (its entries read); a test
        // run records its primitive (one id written).
        const double table = double(t.contexts()) * s.mailbox.entries * MailboxConfig::kEntryBytes;
        const double lookups = double(w[WorkField::mailbox_lookups]), hits = double(w[WorkField::mailbox_hits]);
        pj["mailbox"] = lookups * sram_access_pj(c, table, s.mailbox.entries * 32.0) +
                        (lookups - hits) * sram_access_pj(c, table, 32.0);
    }
    // Traversal units: the ray's setup, and per step a read of the context's ray state and one
    // stack push or pop, each in the unit's SRAM of that kind.
    pj["traversal"] = double(rays) * op.ray_setup +
                      double(w[WorkField::steps] + w[WorkField::rp_steps]) * (sram_access_pj(c, t.contexts() * kContextStateBytes, kContextReadBytes * 8) +
                                         sram_access_pj(c, double(t.contexts()) * t.stack_entries * t.stack_entry_bytes,
                                                        t.stack_entry_bytes * 8.0));
    const bool has_memory = model.contains("l1") || model.contains("ideal_memory");
    if (model.contains("ideal_memory")) {
        pj["l1"] = cache_pj(c, ideal_memory_stats(), model["ideal_memory"], s.l1.size_kib * 1024.0, line);
        pj["l2"] = 0.0;
        pj["dram"] = 0.0;
    } else if (has_memory) {
        double l1 = 0;
        for (const json& cache : model["l1"]) l1 += cache_pj(c, cache_stats(), cache, s.l1.size_kib * 1024.0, line);
        pj["l1"] = l1;
        pj["l2"] = model.contains("l2") ? json(cache_pj(c, cache_stats(), model["l2"], s.l2.size_kib * 1024.0, line)) : json(0.0);
        const json& d = model.value("dram", json::object());
        pj["dram"] = (num(dram_stats(), d, "read_bytes") + num(dram_stats(), d, "write_bytes")) * 8 * dram_pj_per_bit(c);
    } else {
        pj["l1"] = pj["l2"] = pj["dram"] = nullptr;
    }
    if (model.contains("ray_buffer")) {
        const json& rb = model["ray_buffer"];
        const double accesses = num(ray_buffer_stats(), rb, "admitted") + num(ray_buffer_stats(), rb, "parked") +
                                num(ray_buffer_stats(), rb, "taken");
        pj["ray_buffer"] = accesses * sram_access_pj(c, s.treelets.buffer_kib * 1024.0, num(ray_buffer_stats(), rb, "ray_state_bytes") * 8);
    } else {
        pj["ray_buffer"] = s.treelets.enabled && !has_memory ? json(nullptr) : json(0.0);
    }

    for (const auto& [block, e] : technique_energy_pj(s, w, stats)) pj[block] = pj.value(block, 0.0) + e;

    json area = area_json(s, stats);
    const double total_mm2 = area["total_mm2"];
    const double leak_w = total_mm2 * c.leakage_mw_per_mm2 * 1e-3;
    const json rps = summary.value("rays_per_second", json(nullptr));
    const bool timed = rps.is_number() && rps.get<double>() > 0;

    json per_ray_nj = json::object();
    double dynamic_nj = 0;
    bool complete = rays > 0;
    json missing = json::array();
    for (auto it = pj.begin(); it != pj.end(); ++it) {
        per_ray_nj[it.key()] = it->is_number() ? per_ray(it->get<double>(), rays) : json(nullptr);
        if (it->is_number() && rays) dynamic_nj += it->get<double>() / 1000.0 / double(rays);
        else if (!it->is_number()) { complete = false; missing.push_back(it.key()); }
    }
    per_ray_nj["leakage"] = timed ? json(leak_w / rps.get<double>() * 1e9) : json(nullptr);
    if (!timed) { complete = false; missing.push_back("leakage"); }
    const json total_nj = complete ? json(dynamic_nj + per_ray_nj["leakage"].get<double>()) : json(nullptr);
    per_ray_nj["total"] = total_nj;
    const json power = complete && timed ? json(total_nj.get<double>() * 1e-9 * rps.get<double>()) : json(nullptr);
    const json mrays_per_joule = complete ? json(1e3 / total_nj.get<double>()) : json(nullptr);

    json op_pj = {{"ray_setup", op.ray_setup}};
    for (int k = 0; k < kOpKindCount; ++k) op_pj[op_kind_name(OpKind(k))] = op[OpKind(k)];
    stats["energy"] = {
        {"model", "first-order, docs/energy_area.md"},
        {"node_nm", c.node_nm},
        {"vdd", supply_voltage(c)},
        {"energy_scale", energy_scale(c)},
        {"area_scale", area_scale(c)},
        {"dram_kind", kDramKindChoices.name(c.dram_kind)},
        {"dram_pj_per_bit", dram_pj_per_bit(c)},
        {"op_pj", op_pj},
        {"rays", rays},
        {"per_ray_nj", per_ray_nj},
        {"dynamic_nj", rays ? json(dynamic_nj * double(rays)) : json(nullptr)},
        {"leakage_w", leak_w},
        {"power_w", power},
        {"mrays_per_joule", mrays_per_joule},
        {"complete", complete},
        {"missing", missing},
    };
    stats["area"] = area;
    summary["energy_per_ray_nj"] = total_nj;
    summary["mrays_per_joule"] = mrays_per_joule;
    summary["power_w"] = power;
    summary["area_mm2"] = total_mm2;
    // The frame's energy: the RT unit and memory per ray, plus the shader cores (docs/shading.md).
    const json& model_stats = stats.value("model", json::object());
    if (model_stats.contains("shading") && total_nj.is_number())
        summary["energy_per_frame_mj"] =
            (total_nj.get<double>() * double(rays) * 1e3 + model_stats["shading"].value("energy_pj", 0.0)) * 1e-9;
}

const StatBlock& energy_stats() {
    static const StatBlock block{
        "energy",
        {
            {"model", "", "`\"first-order, docs/energy_area.md\"`"},
            {"node_nm", "nm", "the technology node"},
            {"vdd", "V", "the supply voltage used (`energy.vdd`, or the node's nominal)"},
            {"energy_scale", "x", "Stillmaker & Baas energy factor from 45 nm to the node"},
            {"area_scale", "x", "Stillmaker & Baas area factor from 45 nm to the node"},
            {"dram_kind", "", "the DRAM kind (`energy.dram_kind`)"},
            {"dram_pj_per_bit", "pJ/bit", "its energy per bit (or the override)"},
            {"op_pj", "pJ", "`{op: pJ}`: energy of one test of each operation kind (`box`, `triangle`, `anyhit`, `transform`, `cell`, `plane`, `obb`, `sphere`, `capsule`) and one `ray_setup` at the node"},
            {"rays", "rays", "rays the energy is divided by: the rays checked (a sampled run's simulated rays, warm-up included)"},
            {"per_ray_nj", "nJ/ray", "`{block: nJ}`: each operation kind (tests x op energy), `mailbox` (only with `mailbox.entries > 0`: lookups and recorded tests in the mailbox SRAM), the techniques' blocks as in `area.mm2` (decodes per test, scheduler picks per step or warp step, sorted rays, prefetched lines, helper steps' stack hand-overs, stack prefetches' filter compares, mailbox compares, the build unit's rebuilt triangles and refit nodes), `traversal` (ray setup, context-state reads, stack pushes and pops), `l1` (all L1s, or `ideal_memory`), `l2`, `ray_buffer`, `dram`, `leakage` (leakage power over rays/s) and `total` (their sum; `null` unless every block is known)"},
            {"dynamic_nj", "nJ", "dynamic energy of the blocks with counts, summed over the rays"},
            {"leakage_w", "W", "`area.total_mm2 x energy.leakage_mw_per_mm2`"},
            {"power_w", "W", "as `summary.power_w`"},
            {"mrays_per_joule", "Mrays/J", "as `summary.mrays_per_joule`"},
            {"complete", "bool", "every block has counts (false at functional)"},
            {"missing", "list", "the blocks this level cannot price (`l1`, `l2`, `dram`, `leakage` at functional)"},
        }};
    return block;
}

const StatBlock& area_stats() {
    static const StatBlock block{
        "area",
        {
            {"mm2", "mm^2", "`{block: mm^2}`: `l1` (all units, tags in), `l2` (tags in), `ray_buffer` (treelets on), `stacks`, `ray_contexts`, each pipeline kind built, `mailbox` (only with `mailbox.entries > 0`), and what each technique adds (docs/energy_area.md, \"What each technique adds\"): `node_decoder` (compressed nodes), `leaf_decoder` (compressed leaves: block buffers and index logic), `simt_control` (warp scheduler, lane masks, coalescer), `packet_control`, `context_scheduler` (MIMD: a scheduler entry per ray context), `sort_stage` (`dispatch.sort`), `prefetcher` (`treelets.prefetch`), `cooperation` (`traversal.simt.cooperative`: helper maps, t registers, pick and merge compares), `stack_prefetcher` (`traversal.stack_prefetch`: recent-line filters, request queue), `mailbox_compare`, `build_unit` (moving scenes whose frames build: its SRAM and datapath), `obb_fit` (its fit datapath for oriented nodes, obvh2 BLASes)"},
            {"total_mm2", "mm^2", "all blocks"},
            {"sram_mm2", "mm^2", "the SRAM blocks"},
            {"logic_mm2", "mm^2", "the pipelines"},
            {"sram_bytes", "B", "`{block: bytes}`: the on-chip SRAM's data, by block (`l1` all units, `l2`, `ray_buffer`, `stacks`, `ray_contexts`, `mailbox`); what a sweep's SRAM column and Pareto fronts read"},
            {"sram_total_bytes", "B", "the sum of `sram_bytes`"},
        }};
    return block;
}

RTSIM_REGISTER_STAT_BLOCK(energy_stats)
RTSIM_REGISTER_STAT_BLOCK(area_stats)

namespace {

ReportBlock energy_area_report() {
    ReportBlock b;
    b.name = "energy and area";
    b.order = 50;
    b.add = [](json& stats, const ReportInputs& in) { add_energy_area(stats, in.config, in.work, in.rays); };
    b.keys = {{"energy", energy_stats}, {"area", area_stats}};
    return b;
}

}  // namespace

RTSIM_REGISTER_REPORT_BLOCK(energy_area_report())

}  // namespace rtsim
