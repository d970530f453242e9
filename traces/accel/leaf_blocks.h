#pragma once
// Compressed leaves, lossless (docs/accel.md, "Compressed leaves"): a structure's triangles,
// stored as blocks that share their vertices instead of 48-byte HwTriangle records. Each block
// holds the exact fp32 positions of its distinct vertices once (a per-block vertex dictionary)
// and three 8-bit indices per triangle; primitive ids, instance ids and flags are stored once per
// block when they can be (consecutive ids, 16-bit deltas, or a shared value) and per triangle
// otherwise. It follows the idea of Benthin, Wald, Woop & Afra 2018 ("Compressed-leaf bounding
// volume hierarchies", HPG 2018): compress the leaf level, where most of a BVH's bytes are, and
// keep regular nodes above it. What is built here is only the lossless part, a leaf that shares
// its vertices (an indexed triangle leaf, with the vertices local to the block rather than in a
// mesh buffer); their quantised multi-leaf boxes are not. Positions are kept bit for bit, so
// every structure's hits and work counts are unchanged (decoded triangles equal the plain records
// byte for byte; tested).
//
// A block never spans two leaves (builders give their leaves' first triangles), so a leaf step
// fetches exactly its leaf's blocks; structures that reference single triangles (grid, kd-tree,
// octree) fetch the block holding each one. The model fetches the blocks' bytes, so the DRAM and
// cache traffic of the technique is what it measures (docs/architecture.md, rule 3).
//
// Block layout (little endian, each block starts on a 4-byte boundary):
//
//   offset  size        field
//   0       u8          tris: triangles in the block (1..255)
//   1       u8          verts: distinct vertices (1..255, at most 3 x tris)
//   2       u8          mode: bits 0-1 prim ids (0: prim_base + i, 1: u16 deltas, 2: u32 each),
//                       bits 2-3 instance ids, bits 4-5 flags (0: all zero, 1: one shared u32,
//                       2: one u32 per triangle)
//   3       u8          words: the block's size in 4-byte words (header included)
//   4       u32         prim_base
//   8       ...         instance ids (0, 1 or tris x u32), then flags (likewise), then prim ids
//                       (tris x u32 in mode 2), then verts x f32[3] positions, then prim deltas
//                       (tris x u16 in mode 1), then tris x u8[3] vertex indices, zero padding
//                       to the next 4-byte boundary
#include <cstdint>
#include <string>
#include <vector>

#include "traces/accel/accel_image.h"
#include "traces/common/hw_triangle.h"

namespace rtsim {

/// The leaf layout every structure takes (a builder setting of every kind: `rtsim trace
/// --build-set compressed_leaves=true`, a sweep's `build:` axis).
struct LeafConfig {
    /// Store triangles as compressed blocks (region "leaf_blocks") instead of HwTriangle records.
    bool compressed = false;
    /// Largest block: a leaf bigger than this is stored as several blocks. Structures that fetch
    /// single triangles fetch a whole block each and cap it at kSingleFetchBlockBytes.
    uint32_t block_bytes = 256;

    template <class V>
    void visit(V& v) {
        v.flag("compressed_leaves", compressed,
               "Store triangles as lossless compressed blocks (shared vertices, byte indices; Benthin et al. 2018)");
        v.field("leaf_block_bytes", block_bytes, "bytes",
                "Largest compressed block (with compressed_leaves; a longer leaf takes several)", 64, 1020);
    }
};

/// Largest block of a structure that fetches single triangles (grid, kd-tree, octree): one
/// 64-byte line, so a reference's fetch brings at most a line, as a plain triangle does.
inline constexpr uint32_t kSingleFetchBlockBytes = 64;

/// Name of the compressed region (DataKind::triangle, 4-byte words).
inline constexpr const char* kLeafBlocksRegion = "leaf_blocks";

/// Replaces the image's "triangles" region by its compressed blocks (placed again), starting a
/// block at every entry of `leaf_starts` (the first triangles of the leaves, any order; empty: the
/// structure fetches single triangles and blocks are cut by size only). Adds stats["leaf_blocks"].
void compress_leaves(AccelImage& image, std::vector<uint32_t> leaf_starts, const LeafConfig& config);

/// The image's triangle region: "leaf_blocks" when its leaves are compressed, else "triangles"
/// (throws rtsim::Error naming "triangles" if neither is there).
const Region& triangle_region(const AccelImage& image);
/// True when a triangle region's records have the size its name says (48-byte HwTriangle
/// records, or the 4-byte words of compressed blocks).
inline bool triangle_records_ok(const Region& r) {
    return r.record_bytes == (r.name == kLeafBlocksRegion ? 4u : uint32_t(sizeof(HwTriangle)));
}

/// Where a triangle's bytes are: plain HwTriangle records from `base`, or the compressed block(s)
/// holding them.
struct TriangleAddressing {
    uint64_t base = 0;                      ///< address of triangle 0, or of the first block
    const uint32_t* block_of = nullptr;     ///< null: plain records; else the block of each triangle
    const uint64_t* block_start = nullptr;  ///< address of each block, and one past the last

    struct Span {
        uint64_t address;
        uint32_t bytes;
    };
    /// The bytes a step reading triangles [first, first + count) fetches (count > 0).
    Span span(uint32_t first, uint32_t count) const {
        if (!block_of) return {base + uint64_t(first) * sizeof(HwTriangle), uint32_t(sizeof(HwTriangle) * count)};
        const uint32_t b0 = block_of[first], b1 = block_of[first + count - 1];
        return {block_start[b0], uint32_t(block_start[b1 + 1] - block_start[b0])};
    }
};

/// A structure's triangles as its steppers read them: the plain region's records, or the
/// compressed region decoded once when the image is loaded (host memory, not part of the image).
class TriangleStore {
public:
    TriangleStore() = default;
    TriangleStore(TriangleStore&&) = default;  // the decoded array moves with its buffer
    TriangleStore& operator=(TriangleStore&&) = default;
    TriangleStore(const TriangleStore&) = delete;
    TriangleStore& operator=(const TriangleStore&) = delete;

    /// Opens "triangles" or "leaf_blocks", whichever the image holds; throws rtsim::Error naming
    /// `source`, the region and the block on anything malformed.
    static TriangleStore open(const AccelImage& image, const std::string& source);

    const HwTriangle* triangles() const { return m_tris; }
    uint64_t count() const { return m_count; }
    bool compressed() const { return !m_block_of.empty(); }
    TriangleAddressing addressing() const {
        return {m_base, compressed() ? m_block_of.data() : nullptr, compressed() ? m_block_start.data() : nullptr};
    }

private:
    const HwTriangle* m_tris = nullptr;
    uint64_t m_count = 0;
    uint64_t m_base = 0;
    std::vector<HwTriangle> m_decoded;
    std::vector<uint32_t> m_block_of;
    std::vector<uint64_t> m_block_start;
};

/// Decodes a "leaf_blocks" region into triangles; block_of/block_start (optional) receive each
/// triangle's block and each block's byte offset (plus the end). Throws rtsim::Error naming
/// `source` and the block's byte offset on a malformed block.
std::vector<HwTriangle> decode_leaf_blocks(const Region& region, const std::string& source,
                                           std::vector<uint32_t>* block_of = nullptr,
                                           std::vector<uint64_t>* block_start = nullptr);

}  // namespace rtsim
