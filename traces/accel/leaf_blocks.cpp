#include "traces/accel/leaf_blocks.h"

#include <algorithm>
#include <cstring>
#include <utility>

#include "traces/common/error.h"

namespace rtsim {

namespace {

constexpr uint32_t kHeaderBytes = 8;
constexpr uint32_t kMaxTris = 255, kMaxVerts = 255;
enum : uint8_t { kImplicit = 0, kShared16 = 1, kPerTri = 2 };  // 1: u16 deltas (prims) or one shared u32

/// A vertex by its bits: equal keys decode to the same floats (so -0.0 and 0.0 stay apart).
struct VertexKey {
    uint32_t bits[3];
    bool operator==(const VertexKey& o) const { return std::memcmp(bits, o.bits, sizeof(bits)) == 0; }
};

VertexKey key_of(const float v[3]) {
    VertexKey k;
    std::memcpy(k.bits, v, sizeof(k.bits));
    return k;
}

/// What a block of triangles needs: its distinct vertices and how its ids and flags are stored.
struct BlockShape {
    std::vector<VertexKey> verts;
    uint32_t tris = 0;
    uint32_t prim_min = 0, prim_max = 0, prim_first = 0;
    bool prims_consecutive = true, inst_shared = true, flags_shared = true;
    uint32_t inst = 0, flags = 0;

    uint8_t prim_mode() const {
        if (prims_consecutive) return kImplicit;
        return prim_max - prim_min <= 0xFFFF ? kShared16 : kPerTri;
    }
    static uint8_t value_mode(bool shared, uint32_t value) { return !shared ? kPerTri : value ? kShared16 : kImplicit; }
    uint8_t mode() const {
        return uint8_t(prim_mode() | value_mode(inst_shared, inst) << 2 | value_mode(flags_shared, flags) << 4);
    }
    uint32_t bytes() const { return block_bytes(tris, uint32_t(verts.size()), mode()); }

    static uint32_t value_words(uint8_t m, uint32_t tris) { return m == kPerTri ? tris : m == kShared16 ? 1 : 0; }
    static uint32_t block_bytes(uint32_t tris, uint32_t verts, uint8_t mode) {
        const uint8_t pm = mode & 3;
        uint32_t b = kHeaderBytes + 4 * (value_words(mode >> 2 & 3, tris) + value_words(mode >> 4 & 3, tris));
        b += pm == kPerTri ? 4 * tris : 0;
        b += 12 * verts;
        b += pm == kShared16 ? 2 * tris : 0;
        b += 3 * tris;
        return (b + 3) & ~3u;
    }

    /// Adds a triangle (the caller undoes it by copying the shape back when the block is full).
    void add(const HwTriangle& t) {
        for (const float* v : {t.v0, t.v1, t.v2}) {
            const VertexKey k = key_of(v);
            if (std::find(verts.begin(), verts.end(), k) == verts.end()) verts.push_back(k);
        }
        if (tris == 0) {
            prim_min = prim_max = prim_first = t.prim;
            inst = t.inst;
            flags = t.flags;
        } else {
            prims_consecutive = prims_consecutive && t.prim == prim_first + tris;
            prim_min = std::min(prim_min, t.prim);
            prim_max = std::max(prim_max, t.prim);
            inst_shared = inst_shared && t.inst == inst;
            flags_shared = flags_shared && t.flags == flags;
        }
        ++tris;
    }
};

uint8_t vertex_index(const std::vector<VertexKey>& verts, const float v[3]) {
    return uint8_t(std::find(verts.begin(), verts.end(), key_of(v)) - verts.begin());
}

void put32(std::vector<uint8_t>& out, uint32_t v) {
    const size_t at = out.size();
    out.resize(at + 4);
    std::memcpy(&out[at], &v, 4);
}

void put_values(std::vector<uint8_t>& out, uint8_t m, uint32_t shared, const HwTriangle* t, uint32_t n,
                uint32_t HwTriangle::*field) {
    if (m == kShared16) put32(out, shared);
    if (m == kPerTri)
        for (uint32_t i = 0; i < n; ++i) put32(out, t[i].*field);
}

/// Appends one block of triangles t[0, n) of shape s.
void write_block(std::vector<uint8_t>& out, const HwTriangle* t, uint32_t n, const BlockShape& s) {
    const size_t start = out.size();
    const uint8_t mode = s.mode(), pm = mode & 3;
    const uint32_t prim_base = pm == kImplicit ? s.prim_first : s.prim_min;
    out.push_back(uint8_t(n));
    out.push_back(uint8_t(s.verts.size()));
    out.push_back(mode);
    out.push_back(uint8_t(s.bytes() / 4));
    put32(out, prim_base);
    put_values(out, mode >> 2 & 3, s.inst, t, n, &HwTriangle::inst);
    put_values(out, mode >> 4 & 3, s.flags, t, n, &HwTriangle::flags);
    if (pm == kPerTri) put_values(out, kPerTri, 0, t, n, &HwTriangle::prim);
    for (const VertexKey& k : s.verts)
        for (uint32_t b : k.bits) put32(out, b);
    if (pm == kShared16)
        for (uint32_t i = 0; i < n; ++i) {
            const uint16_t d = uint16_t(t[i].prim - prim_base);
            out.push_back(uint8_t(d));
            out.push_back(uint8_t(d >> 8));
        }
    for (uint32_t i = 0; i < n; ++i)
        for (const float* v : {t[i].v0, t[i].v1, t[i].v2}) out.push_back(vertex_index(s.verts, v));
    while ((out.size() - start) % 4) out.push_back(0);
}

/// Encodes triangles [first, end) of one leaf as blocks of at most `max_bytes`; returns the blocks.
uint32_t encode_leaf(std::vector<uint8_t>& out, const HwTriangle* tris, uint32_t first, uint32_t end,
                     uint32_t max_bytes) {
    uint32_t blocks = 0;
    while (first < end) {
        BlockShape s;
        s.add(tris[first]);
        uint32_t n = 1;
        while (first + n < end && n < kMaxTris) {
            BlockShape grown = s;
            grown.add(tris[first + n]);
            if (grown.verts.size() > kMaxVerts || grown.bytes() > max_bytes) break;
            s = std::move(grown);
            ++n;
        }
        write_block(out, tris + first, n, s);
        first += n;
        ++blocks;
    }
    return blocks;
}

struct BlockReader {
    const uint8_t* p;
    const uint8_t* end;
    uint32_t u32(uint32_t at) const {
        uint32_t v;
        std::memcpy(&v, p + at, 4);
        return v;
    }
};

}  // namespace

void compress_leaves(AccelImage& image, std::vector<uint32_t> leaf_starts, const LeafConfig& config) {
    std::sort(leaf_starts.begin(), leaf_starts.end());
    // A structure that fetches single triangles fetches a whole block for each: one line at most.
    const uint32_t max_bytes = leaf_starts.empty() ? std::min(config.block_bytes, kSingleFetchBlockBytes) : config.block_bytes;
    auto it = std::find_if(image.regions.begin(), image.regions.end(), [](const Region& r) { return r.name == "triangles"; });
    require(it != image.regions.end(), "compressed_leaves: structure '" + image.kind + "' has no triangle region");
    const HwTriangle* tris = it->records<HwTriangle>();
    const uint32_t n = uint32_t(it->count);
    std::vector<uint8_t> out;
    out.reserve(it->size_bytes());
    uint64_t blocks = 0;
    size_t next = 0;
    for (uint32_t first = 0; first < n;) {
        while (next < leaf_starts.size() && leaf_starts[next] <= first) ++next;
        const uint32_t end = next < leaf_starts.size() ? std::min(n, leaf_starts[next]) : n;
        blocks += encode_leaf(out, tris, first, end, max_bytes);
        first = end;
    }
    const uint64_t plain_bytes = it->size_bytes();
    Region r;
    r.name = kLeafBlocksRegion;
    r.kind = DataKind::triangle;
    r.record_bytes = 4;
    r.count = out.size() / 4;
    r.layout = layout_of(static_cast<const uint32_t*>(nullptr));
    r.bytes.resize(out.size(), false);
    if (!out.empty()) std::memcpy(r.bytes.data(), out.data(), out.size());
    *it = std::move(r);
    image.place_regions();
    image.stats["leaf_blocks"] = {{"layout", "compressed"},
                             {"block_bytes_max", max_bytes},
                             {"blocks", blocks},
                             {"triangles", n},
                             {"bytes", out.size()},
                             {"plain_bytes", plain_bytes},
                             {"bytes_per_triangle", n ? double(out.size()) / n : 0.0},
                             {"ratio", plain_bytes ? double(out.size()) / double(plain_bytes) : 0.0}};
}

std::vector<HwTriangle> decode_leaf_blocks(const Region& region, const std::string& source,
                                           std::vector<uint32_t>* block_of, std::vector<uint64_t>* block_start) {
    const uint8_t* data = region.bytes.data();
    const uint64_t size = region.size_bytes();
    std::vector<HwTriangle> tris;
    std::vector<std::pair<uint64_t, uint64_t>> starts;  // (first triangle, byte) of each block
    uint32_t block = 0;
    for (uint64_t at = 0; at < size; ++block) {
        starts.emplace_back(tris.size(), at);
        auto fail = [&](const std::string& what) {
            throw Error(source + ": region '" + region.name + "' block at byte " + std::to_string(at) + ": " + what);
        };
        if (size - at < kHeaderBytes) fail("truncated header");
        const BlockReader b{data + at, data + size};
        const uint32_t n = b.p[0], nv = b.p[1], words = b.p[3];
        const uint8_t mode = b.p[2], pm = mode & 3, im = mode >> 2 & 3, fm = mode >> 4 & 3;
        if (n == 0 || nv == 0 || nv > 3 * n) fail("bad counts (" + std::to_string(n) + " triangles, " + std::to_string(nv) + " vertices)");
        if (pm > kPerTri || im > kPerTri || fm > kPerTri || (mode >> 6)) fail("bad mode " + std::to_string(mode));
        if (words * 4 != BlockShape::block_bytes(n, nv, mode)) fail("size " + std::to_string(words * 4) + " does not match its contents");
        if (uint64_t(words) * 4 > size - at) fail("runs past the region's end");
        const uint32_t prim_base = b.u32(4);
        uint32_t off = kHeaderBytes;
        auto values = [&](uint8_t m) {
            const uint32_t o = off;
            off += 4 * BlockShape::value_words(m, n);
            return o;
        };
        const uint32_t inst_at = values(im), flags_at = values(fm), prim_at = values(pm == kPerTri ? kPerTri : kImplicit);
        const uint32_t vert_at = off;
        off += 12 * nv;
        const uint32_t delta_at = off;
        off += pm == kShared16 ? 2 * n : 0;
        const uint32_t index_at = off;
        auto value = [&](uint8_t m, uint32_t o, uint32_t i) { return m == kPerTri ? b.u32(o + 4 * i) : m == kShared16 ? b.u32(o) : 0u; };
        for (uint32_t i = 0; i < n; ++i) {
            HwTriangle t;
            float* v[3] = {t.v0, t.v1, t.v2};
            for (int c = 0; c < 3; ++c) {
                const uint32_t k = b.p[index_at + 3 * i + c];
                if (k >= nv) fail("triangle " + std::to_string(i) + " indexes vertex " + std::to_string(k) + " of " + std::to_string(nv));
                std::memcpy(v[c], b.p + vert_at + 12 * k, 12);
            }
            t.prim = pm == kImplicit  ? prim_base + i
                     : pm == kPerTri ? b.u32(prim_at + 4 * i)
                                     : prim_base + uint32_t(b.p[delta_at + 2 * i] | b.p[delta_at + 2 * i + 1] << 8);
            t.inst = value(im, inst_at, i);
            t.flags = value(fm, flags_at, i);
            tris.push_back(t);
            if (block_of) block_of->push_back(block);
        }
        if (block_start) block_start->push_back(at);
        at += uint64_t(words) * 4;
    }
    if (block_start) block_start->push_back(size);
    // Every primitive id names a triangle of the image (a single-level image stores each scene
    // triangle at least once, and compressed leaves are single-level only): checked here for every
    // block, not only where a ray happens to hit (a prim_base moved out of range).
    for (size_t b = 0; b < starts.size(); ++b) {
        const size_t end = b + 1 < starts.size() ? starts[b + 1].first : tris.size();
        for (size_t i = starts[b].first; i < end; ++i)
            if (tris[i].prim >= tris.size())
                throw Error(source + ": region '" + region.name + "' block at byte " + std::to_string(starts[b].second) +
                            ": triangle " + std::to_string(i - starts[b].first) + " has primitive id " +
                            std::to_string(tris[i].prim) + ", past the " + std::to_string(tris.size()) +
                            " triangles of the image (prim_base " +
                            std::to_string(BlockReader{data + starts[b].second, data + size}.u32(4)) + ")");
    }
    return tris;
}

const Region& triangle_region(const AccelImage& image) {
    return image.has_region(kLeafBlocksRegion) ? image.region(kLeafBlocksRegion) : image.region("triangles");
}

TriangleStore TriangleStore::open(const AccelImage& image, const std::string& source) {
    TriangleStore s;
    if (!image.has_region(kLeafBlocksRegion)) {
        const Region& r = image.region("triangles");
        require(r.kind == DataKind::triangle && r.record_bytes == sizeof(HwTriangle),
                source + ": region 'triangles' is not of 48-byte triangle records");
        s.m_tris = r.records<HwTriangle>();
        s.m_count = r.count;
        s.m_base = r.base;
        return s;
    }
    require(!image.has_region("triangles"), source + ": holds both 'triangles' and '" + kLeafBlocksRegion + "'");
    const Region& r = image.region(kLeafBlocksRegion);
    require(r.kind == DataKind::triangle && r.record_bytes == 4,
            source + ": region '" + std::string(kLeafBlocksRegion) + "' is not of 4-byte triangle words");
    s.m_decoded = decode_leaf_blocks(r, source, &s.m_block_of, &s.m_block_start);
    for (uint64_t& a : s.m_block_start) a += r.base;
    s.m_tris = s.m_decoded.data();
    s.m_count = s.m_decoded.size();
    s.m_base = r.base;
    if (s.m_count == 0) s.m_block_of.clear();
    return s;
}

}  // namespace rtsim
