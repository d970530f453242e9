#pragma once
// The packet unit kind's own config section, traversal.packet (packet_unit.h).
#include <cstdint>

namespace rtsim {

struct PacketConfig {
    uint32_t lanes = 8;  ///< rays per packet, sharing one traversal stack
    /// The hybrid's threshold (Benthin et al. 2012): a packet whose active rays at a node are
    /// fewer than this fraction of its rays splits into single rays; 0: never
    double split_below = 0.0;

    template <class V>
    void visit(V& v) {
        v.field("lanes", lanes, "rays", "Rays per packet, sharing one traversal stack; traversal.ray_contexts is a whole number of packets (0 there: 16 rounded up to whole packets)", 4, 64);
        v.field("split_below", split_below, "fraction", "A packet whose active rays at a node are fewer than this fraction of its rays splits, its rays finishing alone one after the other (Benthin et al. 2012's hybrid); 0: never", 0.0, 1.0);
    }
};

}  // namespace rtsim
