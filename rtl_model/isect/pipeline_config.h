#pragma once
// Configuration of a test pipeline (box, triangle, any-hit, ...): timing only; the arithmetic
// is traces/isect (docs/architecture.md, rule 1: one arithmetic).
#include <cstdint>

#include "rtl_model/common/choice.h"

namespace rtsim {

enum class Sharing : uint8_t { per_unit = 0, shared = 1 };
inline constexpr Choices<Sharing, 2> kSharingChoices{{"private", "shared"}};

struct PipelineConfig {
    uint32_t latency = 8;              ///< cycles from issue to result
    uint32_t initiation_interval = 1;  ///< cycles between issues into one pipeline
    uint32_t width = 1;                ///< tests per issue (a wide node's boxes take ceil(n / width) issues)
    Sharing sharing = Sharing::per_unit;  ///< one pipeline per unit ("private"), or a shared pool
    uint32_t shared_count = 4;         ///< pipelines in the shared pool (sharing = shared)

    bool shared() const { return sharing == Sharing::shared; }

    template <class V>
    void visit(V& v) {
        v.field("latency", latency, "cycles", "Cycles from issue to result", 1, 1000);
        v.field("initiation_interval", initiation_interval, "cycles", "Cycles between two issues into one pipeline", 1, 1000);
        v.field("width", width, "tests", "Tests per issue (a node's child boxes take ceil(children / width) issues; width 2 tests a binary node in one issue)", 1, 64);
        v.choice("sharing", sharing, kSharingChoices, "One pipeline per traversal unit, or a pool shared by all units");
        v.field("shared_count", shared_count, "pipelines", "Pipelines in the shared pool (sharing = shared)", 1, 1024);
    }
};

}  // namespace rtsim
