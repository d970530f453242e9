// The first-order energy and area model (sim/report/energy_area.h, docs/energy_area.md): the
// 45 nm reference reproduces Horowitz's figures, scaling follows Stillmaker & Baas, counts are
// priced block by block, and what a level cannot know is null.
#include <gtest/gtest.h>

#include "sim/report/energy_area.h"

namespace rtsim {
namespace {

using nlohmann::json;

EnergyConfig at_45nm() {
    EnergyConfig c;
    c.node_nm = 45;
    return c;
}

TEST(EnergyArea, ReferenceNodeIsHorowitz) {
    const EnergyConfig c = at_45nm();
    EXPECT_NEAR(energy_scale(c), 1.0, 1e-9);
    EXPECT_NEAR(area_scale(c), 1.0, 1e-9);
    // Horowitz 2014: 8 KiB 64-bit read 10 pJ, 32 KiB 20 pJ, 1 MiB 100 pJ (our fit: 113 pJ).
    EXPECT_NEAR(sram_access_pj(c, 8192, 64), 10.0, 1e-9);
    EXPECT_NEAR(sram_access_pj(c, 32768, 64), 20.0, 1e-9);
    EXPECT_NEAR(sram_access_pj(c, 1 << 20, 64), 113.1, 0.1);
    // A box test: (6 add x 0.9 + 7 mul x 3.7 + 9 cmp x 0.1) x 1.5 overhead = 48.3 pJ.
    EXPECT_NEAR(op_energies(c)[OpKind::box], 48.3, 1e-9);
    // A triangle test: (22 x 0.9 + (20 + 3 x 4) x 3.7 + 12 x 0.1) x 1.5 = 209.1 pJ.
    EXPECT_NEAR(op_energies(c)[OpKind::triangle], 209.1, 1e-9);
}

TEST(EnergyArea, SmallerNodesCostLess) {
    EnergyConfig c = at_45nm();
    double previous_e = energy_scale(c), previous_a = area_scale(c);
    for (double nm : {32.0, 20.0, 16.0, 14.0, 12.0, 10.0, 7.0}) {
        c.node_nm = nm;
        EXPECT_LT(energy_scale(c), previous_e) << nm;
        EXPECT_LT(area_scale(c), previous_a) << nm;
        previous_e = energy_scale(c);
        previous_a = area_scale(c);
    }
    c.node_nm = 7;
    EXPECT_NEAR(area_scale(c), 0.059, 1e-9);  // Stillmaker & Baas, Table 3
    EXPECT_NEAR(supply_voltage(c), 0.7, 1e-9);
    // A higher supply voltage costs more energy at the same node.
    const double nominal = energy_scale(c);
    c.vdd = 0.9;
    EXPECT_GT(energy_scale(c), nominal);
}

TEST(EnergyArea, DramKindsAndOverride) {
    EnergyConfig c;
    c.dram_kind = DramKind::hbm2;
    const double hbm = dram_pj_per_bit(c);
    c.dram_kind = DramKind::gddr6;
    EXPECT_LT(hbm, dram_pj_per_bit(c));
    c.dram_pj_per_bit = 2.0;
    EXPECT_EQ(dram_pj_per_bit(c), 2.0);
}

json timed_stats(double dram_bytes) {
    json cache = {{"reads", 1000}, {"read_hits", 900}, {"merged", 0}, {"writes", 10}, {"write_bytes", 200}};
    return {{"summary", {{"rays_per_second", 1e8}}},
            {"instantiated", json::array()},
            {"model",
             {{"l1", {{"l1_0", cache}}},
              {"l2", cache},
              {"dram", {{"read_bytes", dram_bytes}, {"write_bytes", 0}}}}}};
}

TEST(EnergyArea, PricesEveryBlockAndSums) {
    SimConfig s;
    WorkTotals w;
    w[WorkField::box_tests] = 2000;
    w[WorkField::tri_tests] = 100;
    w[WorkField::steps] = 1000;
    json stats = timed_stats(64000);
    add_energy_area(stats, s, w, 100);
    const json& e = stats["energy"]["per_ray_nj"];
    const OpEnergies op = op_energies(s.energy);
    EXPECT_NEAR(e["box"].get<double>(), 20 * op[OpKind::box] / 1000, 1e-12);
    EXPECT_NEAR(e["triangle"].get<double>(), op[OpKind::triangle] / 1000, 1e-12);
    // 640 DRAM bytes per ray x 8 bits x 7.5 pJ (GDDR6) = 38.4 nJ.
    EXPECT_NEAR(e["dram"].get<double>(), 38.4, 1e-9);
    double sum = 0;
    for (auto it = e.begin(); it != e.end(); ++it)
        if (it.key() != "total") sum += it->get<double>();
    EXPECT_NEAR(e["total"].get<double>(), sum, 1e-9);
    EXPECT_NEAR(stats["summary"]["mrays_per_joule"].get<double>(), 1e3 / sum, 1e-9);
    EXPECT_NEAR(stats["summary"]["power_w"].get<double>(), sum * 1e-9 * 1e8, 1e-9);
    EXPECT_TRUE(stats["energy"]["complete"].get<bool>());
    // Twice the DRAM traffic costs more energy per ray; the area does not change.
    json more = timed_stats(128000);
    add_energy_area(more, s, w, 100);
    EXPECT_GT(more["summary"]["energy_per_ray_nj"].get<double>(), stats["summary"]["energy_per_ray_nj"].get<double>());
    EXPECT_EQ(more["summary"]["area_mm2"], stats["summary"]["area_mm2"]);
}

TEST(EnergyArea, FunctionalLevelReportsWhatItCan) {
    SimConfig s;
    s.fidelity = Fidelity::functional;
    WorkTotals w;
    w[WorkField::box_tests] = 10;
    json stats = {{"summary", {{"rays_per_second", nullptr}}}, {"model", json::object()}};
    add_energy_area(stats, s, w, 5);
    EXPECT_TRUE(stats["energy"]["per_ray_nj"]["box"].is_number());
    EXPECT_TRUE(stats["energy"]["per_ray_nj"]["dram"].is_null());
    EXPECT_TRUE(stats["summary"]["energy_per_ray_nj"].is_null());
    EXPECT_TRUE(stats["summary"]["power_w"].is_null());
    EXPECT_GT(stats["summary"]["area_mm2"].get<double>(), 0.0);
}

TEST(EnergyArea, AreaGrowsWithWhatIsBuilt) {
    SimConfig s;
    json stats = timed_stats(0);
    add_energy_area(stats, s, {}, 1);
    SimConfig bigger = s;
    bigger.l2.size_kib *= 2;
    json stats2 = timed_stats(0);
    add_energy_area(stats2, bigger, {}, 1);
    EXPECT_NEAR(stats2["area"]["mm2"]["l2"].get<double>(), 2 * stats["area"]["mm2"]["l2"].get<double>(), 1e-12);
    SimConfig treelets = s;
    treelets.treelets.enabled = true;
    json stats3 = timed_stats(0);
    add_energy_area(stats3, treelets, {}, 1);
    EXPECT_EQ(stats["area"]["mm2"]["ray_buffer"].get<double>(), 0.0);
    EXPECT_GT(stats3["area"]["mm2"]["ray_buffer"].get<double>(), 0.0);
    // 8 KiB at 45 nm is 5.8 / 128 mm^2; at 7 nm x 0.059.
    EXPECT_NEAR(sram_mm2(s.energy, 8192), 5.8 / 128 * 0.059, 1e-12);
}

}  // namespace
}  // namespace rtsim
