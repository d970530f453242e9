#pragma once
// A first-order energy and area model of the accelerator (docs/energy_area.md), computed after a
// run from its counts and config: the timed model never sees it. Operation energies come from the
// floating-point operation counts of our arithmetic (traces/isect/) priced with Horowitz's 45 nm
// figures (ISSCC 2014); SRAM energy and area follow Horowitz's SRAM points and a 45 nm cell; DRAM
// is priced per bit by kind; everything is scaled to the configured node with Stillmaker & Baas
// (2017). Every level reports what its counts allow: the functional level has no caches and no
// time, so its memory energy, leakage, energy per ray and power are null.
#include <array>
#include <cstdint>

#include <nlohmann/json.hpp>

#include "rtl_model/common/stats.h"
#include "sim/config/config.h"
#include "traces/common/work_counts.h"

namespace rtsim {

/// Energy of one test of each operation kind at the configured node, pJ (datapath overhead in).
struct OpEnergies {
    std::array<double, kOpKindCount> test{};  ///< one test of each operation kind
    double ray_setup = 0;                     ///< a ray's precomputation
    double operator[](OpKind kind) const { return test[size_t(kind)]; }
};

/// Energy scale from 45 nm (1.0 V) to the configured node and voltage (Stillmaker & Baas 2017).
double energy_scale(const EnergyConfig& c);
/// Area scale from 45 nm to the configured node (Stillmaker & Baas 2017).
double area_scale(const EnergyConfig& c);
/// The supply voltage used: energy.vdd, or the node's nominal voltage when it is 0.
double supply_voltage(const EnergyConfig& c);
/// DRAM energy per bit: energy.dram_pj_per_bit, or the kind's published figure when it is 0.
double dram_pj_per_bit(const EnergyConfig& c);
OpEnergies op_energies(const EnergyConfig& c);
/// Energy of one access of `bits` to an SRAM of `bytes` at the configured node, pJ.
double sram_access_pj(const EnergyConfig& c, double bytes, double bits);
/// Area of an SRAM of `bytes` of data at the configured node, mm^2 (without tags).
double sram_mm2(const EnergyConfig& c, double bytes);

/// Logic of `adds` fp32 adders, `muls` multipliers and `cmps` comparators (integer adds, muxes)
/// with the datapath overhead: its area at the configured node, mm^2, and one use's energy, pJ.
double logic_mm2(const EnergyConfig& c, double adds, double muls, double cmps);
double logic_pj(const EnergyConfig& c, double adds, double muls, double cmps);

/// The box pipelines at a mantissa width (traversal.box_precision_bits; 0: fp32): one test's
/// energy, pJ, and all box pipelines' area, mm^2 (docs/energy_area.md, "Reduced-precision box
/// pipeline": adders and comparators scale with the word width, multipliers with the significand
/// width squared).
struct BoxPipelineCost {
    double test_pj = 0, mm2 = 0;
};
/// The box pipeline the config builds: fp32, `traversal.box_precision_bits` wide, or with
/// `traversal.quantized_boxes` an integer one (AQB8); `fp32` prices the fp32 one whatever is set.
BoxPipelineCost box_pipeline_cost(const SimConfig& config, bool fp32 = false);

/// Adds `energy` and `area` to stats and `energy_per_ray_nj`, `mrays_per_joule`, `area_mm2` and
/// `power_w` to stats["summary"] (null where the level cannot know them). Reads stats["model"],
/// stats["summary"] (rays_per_second: the estimate of a sampled run) and stats["instantiated"].
void add_energy_area(nlohmann::json& stats, const SimConfig& config, const WorkTotals& work, uint64_t rays);

/// The area model's total for a config, mm^2 (`area.total_mm2`; `instantiated` as in stats.json:
/// it says whether the any-hit pipelines are built). The verdict prices each knob with it.
double area_total_mm2(const SimConfig& config, const nlohmann::json& instantiated);

/// stats.json "energy" and "area", declared once.
const StatBlock& energy_stats();
const StatBlock& area_stats();

}  // namespace rtsim
