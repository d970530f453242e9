#pragma once
// Configuration of treelet scheduling with ray buffers (Aila & Karras 2010; STRaTA, Kopta et
// al. 2013; docs/treelets.md).
#include <cstdint>

#include "rtl_model/common/choice.h"

namespace rtsim {

enum class TreeletPolicy : uint8_t { largest = 0, oldest = 1, round_robin = 2 };
inline constexpr Choices<TreeletPolicy, 3> kTreeletPolicyChoices{{"largest", "oldest", "round_robin"}};
/// Which cache treelet prefetches fill (Chou, Nowicki & Aamodt 2023 prefetch into the RT unit's L1).
enum class PrefetchInto : uint8_t { l1 = 0, l2 = 1 };
inline constexpr Choices<PrefetchInto, 2> kPrefetchIntoChoices{{"l1", "l2"}};

struct TreeletConfig {
    bool enabled = false;             ///< queue rays per treelet in the ray buffer
    uint32_t treelet_kib = 16;        ///< byte budget per treelet (nodes + leaf triangles)
    uint32_t buffer_kib = 512;        ///< ray buffer SRAM capacity
    TreeletPolicy policy = TreeletPolicy::largest;  ///< which queue a free unit runs next
    uint32_t threshold = 64;          ///< rays a queue needs before it is worth running
    uint32_t latency = 4;             ///< ray buffer SRAM access latency
    uint32_t bytes_per_cycle = 512;   ///< ray buffer SRAM bandwidth (banked: 8 units x 64 B)
    uint32_t idle_poll_cycles = 32;   ///< how often an idle unit looks for work again
    uint32_t max_rays_in_flight = 0;  ///< rays admitted at once (0: what the SRAM and contexts hold)
    uint32_t admit_outstanding = 16;  ///< ray-record reads in flight while admitting rays
    uint32_t quantum_cycles = 16;     ///< approx with treelets: the units' quantum is at most this
    bool prefetch = false;            ///< request a treelet's lines when a unit enters it (Chou et al. 2023)
    uint32_t prefetch_lines = 0;      ///< lines requested per treelet entry, root first (0: the whole treelet)
    PrefetchInto prefetch_into = PrefetchInto::l1;  ///< the cache prefetched lines are filled into

    template <class V>
    void visit(V& v) {
        v.flag("enabled", enabled, "Treelet scheduling: rays queue per treelet in the ray buffer SRAM");
        v.field("treelet_kib", treelet_kib, "KiB", "Byte budget per treelet (nodes and their leaf triangles)", 1, 1u << 20);
        v.field("buffer_kib", buffer_kib, "KiB", "Ray buffer SRAM capacity; rays beyond it overflow to DRAM", 1, 1u << 22);
        v.choice("policy", policy, kTreeletPolicyChoices, "Queue a free unit runs next: largest queue, oldest waiting ray, or round robin");
        v.field("threshold", threshold, "rays", "Queues of at least this many rays are preferred (oldest, round_robin); shorter ones run only when no queue is that long. No effect with largest", 1, 1u << 20);
        v.field("latency", latency, "cycles", "Ray buffer SRAM access latency", 1, 1000);
        v.field("bytes_per_cycle", bytes_per_cycle, "B/cycle", "Ray buffer SRAM bandwidth", 1, 4096);
        v.field("idle_poll_cycles", idle_poll_cycles, "cycles", "How often a unit with no rays looks for a queue again", 1, 100000);
        v.field("max_rays_in_flight", max_rays_in_flight, "rays", "Rays admitted into the machine at once; beyond what the SRAM holds, queues overflow to DRAM (0: SRAM capacity plus the ray contexts, never overflows)", 0, 1u << 30);
        v.field("admit_outstanding", admit_outstanding, "reads", "Ray-record reads the ray buffer keeps in flight while admitting new rays (a streaming engine, one read issued per cycle)", 1, 4096);
        v.field("quantum_cycles", quantum_cycles, "cycles", "At the approx level with treelets, the units (and the admission engine) run ahead of each other by at most this many cycles (the smaller of this and quantum_cycles): treelet queues' dynamics depend on the order of parks and takes, and longer quanta made approx up to 37% off detailed (docs/fidelity.md)", 1, 1u << 20);
        v.flag("prefetch", prefetch, "Treelet prefetching (Chou, Nowicki & Aamodt 2023): when a unit starts a treelet's queue, or without treelet queues (treelets.enabled false) when a ray steps into a treelet, the treelet's lines are requested ahead of its rays (docs/treelets.md)");
        v.field("prefetch_lines", prefetch_lines, "lines", "Lines prefetched per treelet entry, in the order rays first read them (the treelet's root first); 0: the whole treelet", 0, 1u << 16);
        v.choice("prefetch_into", prefetch_into, kPrefetchIntoChoices, "Cache the prefetched lines are filled into: the unit's l1 or the shared l2");
    }
};

}  // namespace rtsim
