// A throwaway traversal unit kind, registered from this test-only folder and nowhere else: the
// proof that adding a kind touches its own folder only (docs/architecture.md, "Adding a traversal
// unit kind"). It runs as a MIMD unit does, has its own config section (traversal.probe.tag),
// writes its own stats block (probe_tag, echoed) and declares a need a MIMD unit has not (no
// treelet queues), so the resolution step must refuse treelets on it from the rules table.
#include "rtl_model/traversal/mimd/mimd_unit.h"
#include "rtl_model/traversal/unit_kind.h"

namespace rtsim {
namespace {

struct ProbeConfig {
    uint32_t tag = 7;  ///< a number the probe writes into its stats

    template <class V>
    void visit(V& v) {
        v.field("tag", tag, "", "A number the probe unit writes into its stats (a test of unit kinds' own sections)",
                0, 1000);
    }
};

class ProbeUnit final : public MimdUnit {
public:
    ProbeUnit(const char* name, const UnitSetup& setup, uint32_t index)
        : MimdUnit(name, setup, index), m_tag(setup.config.kind_config<ProbeConfig>().tag) {}
    nlohmann::json stats_json(Cycle total_cycles) const override {
        nlohmann::json j = MimdUnit::stats_json(total_cycles);
        j["probe_tag"] = m_tag;
        return j;
    }

private:
    uint32_t m_tag;
};

const StatBlock& probe_stats() {
    static const StatBlock block{"model.units.<unit> (probe)", {{"probe_tag", "", "traversal.probe.tag, echoed"}}};
    return block;
}

UnitKind probe_kind() {
    UnitKind k;
    k.name = "probe";
    k.summary = "a MIMD unit with a section and stats of its own (a test of unit kinds)";
    k.make_unit = [](const char* name, const UnitSetup& setup, uint32_t index) -> std::unique_ptr<TraversalUnit> {
        return std::make_unique<ProbeUnit>(name, setup, index);
    };
    k.section<ProbeConfig>();
    k.stats = &probe_stats();
    k.needs.treelet_queues = false;
    return k;
}

}  // namespace

RTSIM_REGISTER_UNIT_KIND(probe_kind())
RTSIM_REGISTER_STAT_BLOCK(probe_stats)

}  // namespace rtsim
