#pragma once
// The packet unit kind's own config section, traversal.packet (packet_unit.h).
#include <cstdint>

#include "rtl_model/common/choice.h"
#include "traces/accel/packet_stepper.h"

namespace rtsim {

inline constexpr Choices<SplitWalks, 2> kSplitWalksChoices{{"serial", "lanes"}};

struct PacketConfig {
    uint32_t lanes = 8;  ///< rays per packet, sharing one traversal stack
    /// The hybrid's threshold (Benthin et al. 2012): a packet whose active rays at a node are
    /// fewer than this fraction of its rays splits into single rays; 0: never
    double split_below = 0.0;
    /// How a split packet's rays walk: one after another on the packet's context ("serial"), or
    /// each on its own lane of the packet at once ("lanes": the lanes its other rays left free)
    SplitWalks split_walks = SplitWalks::serial;

    template <class V>
    void visit(V& v) {
        v.field("lanes", lanes, "rays", "Rays per packet, sharing one traversal stack; traversal.ray_contexts is a whole number of packets (0 there: 16 rounded up to whole packets)", 4, 64);
        v.field("split_below", split_below, "fraction", "A packet whose active rays at a node are fewer than this fraction of its rays splits, its rays finishing alone as traversal.packet.split_walks says (Benthin et al. 2012's hybrid); 0: never", 0.0, 1.0);
        v.choice("split_walks", split_walks, kSplitWalksChoices, "How a split packet's rays walk alone: serial (one after another on the packet's context) or lanes (each on its own lane of the packet at once, in the lanes the packet's other rays left free; Benthin et al. 2012's single-ray mode with the packet's contexts kept busy)");
    }
};

}  // namespace rtsim
