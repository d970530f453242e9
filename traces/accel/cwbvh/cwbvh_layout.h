#pragma once
// Compressed wide BVH nodes (docs/accel.md, "cwbvh8, cwbvh6"), child boxes quantised to 8 bits
// against the node's frame (quantize.h).
//
// CwNode8, 80 bytes: Ylitie, Karras & Laine 2017, "Efficient incoherent ray traversal on GPUs
// through compressed wide BVHs", Figure 2:
//   0  float   p[3]        frame origin (the node box's lower corner)
//   12 uint8   e[3]        per-axis scale exponent bytes: scale 2^(e - 127)
//   15 uint8   imask       bit s: slot s is an interior node
//   16 uint32  base_node   index of the first interior child (the others follow in slot order)
//   20 uint32  base_tri    index of the first triangle of the node's leaves
//   24 uint8   meta[8]     per slot (below)
//   32 uint8   qlo[3][8]   quantised lower bounds: x of slots 0..7, then y, then z
//   56 uint8   qhi[3][8]   quantised upper bounds
//
// CwNode6, 64 bytes: a 6-wide node in the spirit of Intel Xe's BVH6 (64-byte nodes, 8-bit
// quantised boxes). Six children's boxes take 36 bytes, the frame 15, the meta bytes 6: 7 bytes
// remain for both bases, so they share a 56-bit field of two 28-bit indices (up to 2^28 nodes
// and triangles, 12 GiB of triangles), and the interior mask, redundant with meta, is dropped:
//   0  float   p[3]        frame origin
//   12 uint8   e[3]        exponent bytes
//   15 uint8   meta[6]     per slot (below)
//   21 uint8   bases[7]    little-endian 56 bits: base_node = bits 0..27, base_tri = bits 28..55
//   28 uint8   qlo[3][6]   quantised lower bounds per axis
//   46 uint8   qhi[3][6]   quantised upper bounds per axis
//
// meta (Ylitie et al. 2017): 0 = empty slot; interior child: 0b001 in the top 3 bits and slot + 24
// in the low 5, its node index base_node + (interior children in lower slots); leaf: its triangle
// count in unary in the top 3 bits (0b001, 0b011, 0b111: 1 to 3 triangles) and its first triangle's
// offset from base_tri in the low 5 (offset + count <= 3 x width). Leaves of more than 3 triangles
// cannot be encoded: the builder splits them (wide_tree.h, split_large_leaves).
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "traces/accel/cwbvh/quantize.h"
#include "traces/common/record_layout.h"

namespace rtsim {

struct alignas(16) CwNode8 {
    float p[3];
    uint8_t e[3];
    uint8_t imask;
    uint32_t base_node;
    uint32_t base_tri;
    uint8_t meta[8];
    uint8_t qlo[3][8];
    uint8_t qhi[3][8];
};
static_assert(sizeof(CwNode8) == 80, "CwNode8 must be 80 bytes");
inline RecordLayout layout_of(const CwNode8*) {
    return {RTSIM_FIELD(CwNode8, p),         RTSIM_FIELD(CwNode8, e),        RTSIM_FIELD(CwNode8, imask),
            RTSIM_FIELD(CwNode8, base_node), RTSIM_FIELD(CwNode8, base_tri), RTSIM_FIELD(CwNode8, meta),
            RTSIM_FIELD(CwNode8, qlo),       RTSIM_FIELD(CwNode8, qhi)};
}

struct alignas(16) CwNode6 {
    float p[3];
    uint8_t e[3];
    uint8_t meta[6];
    uint8_t bases[7];
    uint8_t qlo[3][6];
    uint8_t qhi[3][6];

    static constexpr uint64_t kIndexLimit = 1ull << 28;
    uint64_t packed() const {
        uint64_t v = 0;
        std::memcpy(&v, bases, 7);  // little-endian hosts (x86, ARM): the layout's byte order
        return v;
    }
    uint32_t base_node() const { return uint32_t(packed() & (kIndexLimit - 1)); }
    uint32_t base_tri() const { return uint32_t(packed() >> 28); }
    void set_bases(uint32_t node, uint32_t tri) {
        const uint64_t v = uint64_t(node) | uint64_t(tri) << 28;
        std::memcpy(bases, &v, 7);
    }
};
static_assert(sizeof(CwNode6) == 64, "CwNode6 must be 64 bytes");
/// bases: base_node | base_tri << 28, 56 bits little-endian (read them with base_node(), base_tri()).
inline RecordLayout layout_of(const CwNode6*) {
    return {RTSIM_FIELD(CwNode6, p),     RTSIM_FIELD(CwNode6, e),   RTSIM_FIELD(CwNode6, meta),
            RTSIM_FIELD(CwNode6, bases), RTSIM_FIELD(CwNode6, qlo), RTSIM_FIELD(CwNode6, qhi)};
}
static_assert(offsetof(CwNode6, bases) == 21 && offsetof(CwNode6, qlo) == 28, "CwNode6 byte offsets");
static_assert(offsetof(CwNode8, meta) == 24 && offsetof(CwNode8, qhi) == 56, "CwNode8 byte offsets");

/// meta byte of an interior child in slot s, and of a leaf of `count` (1..3) triangles at
/// offset `offset` (0..31) from base_tri.
constexpr uint8_t meta_interior(int slot) { return uint8_t(0x20 | (24 + slot)); }
constexpr uint8_t meta_leaf(uint32_t count, uint32_t offset) { return uint8_t(((1u << count) - 1) << 5 | offset); }
/// Decoding: empty, interior (low 5 bits >= 24), else a leaf of popcount(meta >> 5) triangles.
constexpr bool meta_is_interior(uint8_t m) { return (m >> 5) == 1 && (m & 31) >= 24; }
constexpr uint32_t meta_leaf_count(uint8_t m) { return (m >> 5 & 1u) + (m >> 6 & 1u) + (m >> 7 & 1u); }
constexpr uint32_t meta_leaf_offset(uint8_t m) { return m & 31u; }

}  // namespace rtsim
