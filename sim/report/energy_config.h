#pragma once
// Configuration of the first-order energy and area model (sim/report/energy_area.h,
// docs/energy_area.md). Owned by the harness: the model is computed after a run from its counts
// and this config, so the timed blocks never see it. Every reference figure is at 45 nm (Horowitz,
// "Computing's energy problem", ISSCC 2014) and is scaled to `node_nm` with Stillmaker & Baas 2017
// ("Scaling equations for the accurate prediction of CMOS device performance from 180 nm to 7 nm",
// Integration 58); docs/energy_area.md gives each number's source.
#include <cstdint>

#include "rtl_model/common/choice.h"

namespace rtsim {

/// DRAM kinds with a published energy per bit (docs/energy_area.md, "DRAM").
enum class DramKind : uint8_t { gddr6 = 0, lpddr5 = 1, hbm2 = 2, ddr4 = 3 };
inline constexpr Choices<DramKind, 4> kDramKindChoices{{"gddr6", "lpddr5", "hbm2", "ddr4"}};

struct EnergyConfig {
    double node_nm = 7.0;                ///< technology node; figures are scaled from 45 nm to it
    double vdd = 0.0;                    ///< supply voltage; 0: the node's nominal voltage
    DramKind dram_kind = DramKind::gddr6;///< picks the DRAM energy per bit
    double dram_pj_per_bit = 0.0;        ///< overrides the kind's energy per bit; 0: the kind's figure
    double fp_add_pj = 0.9;              ///< 32-bit FP add at 45 nm (Horowitz 2014)
    double fp_mul_pj = 3.7;              ///< 32-bit FP multiply at 45 nm (Horowitz 2014)
    double cmp_pj = 0.1;                 ///< compare / min / max at 45 nm, as a 32-bit integer add (Horowitz 2014)
    double fp_add_um2 = 4184.0;          ///< 32-bit FP adder area at 45 nm (Horowitz 2014)
    double fp_mul_um2 = 7700.0;          ///< 32-bit FP multiplier area at 45 nm (Horowitz 2014)
    double cmp_um2 = 137.0;              ///< comparator area at 45 nm, as a 32-bit integer adder (Horowitz 2014)
    double datapath_overhead = 1.5;      ///< pipeline registers, operand muxes and control, x arithmetic
    double sram_pj_64b = 10.0;           ///< 64-bit read of an 8 KiB SRAM at 45 nm (Horowitz 2014)
    double sram_size_exponent = 0.5;     ///< SRAM access energy grows as (size / 8 KiB)^exponent
    double sram_mm2_per_mib = 5.8;       ///< SRAM area per MiB at 45 nm (0.346 um^2 cell / 50% array efficiency)
    double sram_tag_overhead = 0.08;     ///< cache tag and state bits, as a fraction of data bits
    double leakage_mw_per_mm2 = 50.0;    ///< static power per mm^2 at the configured node (not scaled)

    template <class V>
    void visit(V& v) {
        v.field("node_nm", node_nm, "nm", "Technology node; 45 nm reference figures are scaled to it (Stillmaker & Baas 2017)", 7, 130);
        v.field("vdd", vdd, "V", "Supply voltage for the energy scaling (0: the node's nominal voltage, docs/energy_area.md)", 0, 2);
        v.choice("dram_kind", dram_kind, kDramKindChoices, "DRAM kind: picks the energy per bit moved (docs/energy_area.md)");
        v.field("dram_pj_per_bit", dram_pj_per_bit, "pJ/bit", "DRAM energy per bit read or written, overriding the kind's figure (0: the kind's)", 0, 1000);
        v.field("fp_add_pj", fp_add_pj, "pJ", "32-bit floating-point add (or subtract) at 45 nm", 0, 1000);
        v.field("fp_mul_pj", fp_mul_pj, "pJ", "32-bit floating-point multiply at 45 nm", 0, 1000);
        v.field("cmp_pj", cmp_pj, "pJ", "Compare, min or max of two floats at 45 nm (a 32-bit integer add)", 0, 1000);
        v.field("fp_add_um2", fp_add_um2, "um^2", "32-bit floating-point adder area at 45 nm", 0, 1e7);
        v.field("fp_mul_um2", fp_mul_um2, "um^2", "32-bit floating-point multiplier area at 45 nm", 0, 1e7);
        v.field("cmp_um2", cmp_um2, "um^2", "Comparator area at 45 nm (a 32-bit integer adder)", 0, 1e7);
        v.field("datapath_overhead", datapath_overhead, "x", "Pipeline registers, operand muxes and control, as a multiple of the arithmetic's energy and area", 1, 100);
        v.field("sram_pj_64b", sram_pj_64b, "pJ", "64-bit read of an 8 KiB SRAM at 45 nm (wider accesses scale per bit)", 0, 10000);
        v.field("sram_size_exponent", sram_size_exponent, "", "SRAM access energy grows as (size / 8 KiB) to this power", 0, 2);
        v.field("sram_mm2_per_mib", sram_mm2_per_mib, "mm^2/MiB", "SRAM area per MiB of data at 45 nm", 0, 1000);
        v.field("sram_tag_overhead", sram_tag_overhead, "fraction", "Cache tag and state bits as a fraction of data bits (area and access energy)", 0, 1);
        v.field("leakage_mw_per_mm2", leakage_mw_per_mm2, "mW/mm^2", "Static (leakage) power per mm^2 of SRAM and datapath at the configured node", 0, 10000);
    }
};

}  // namespace rtsim
