#pragma once
// What an acceleration-structure builder produces for the hardware (docs/accel.md): named
// regions of fixed-size records (nodes, triangles, primitive references, cells, instances) in
// documented byte layouts, each at an address in the accelerator's memory. The image travels in
// the trace; the model's memory map is derived from it (docs/architecture.md, rule 3: one memory
// image, the addresses the caches and DRAM see).
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "traces/accel/aligned_bytes.h"
#include "traces/common/aabb.h"
#include "traces/common/data_kind.h"
#include "traces/common/record_layout.h"

namespace rtsim {

struct Region {
    std::string name;                ///< "nodes", "triangles", "prim_refs", "cells", ...
    DataKind kind = DataKind::node;  ///< what the caches and DRAM count its bytes as
    uint32_t record_bytes = 0;       ///< size of one record (its layout: docs/accel.md)
    uint64_t count = 0;              ///< records
    uint64_t base = 0;               ///< address of record 0 (AccelImage::place_regions)
    RecordLayout layout;             ///< its fields (the record struct's layout_of); empty: raw bytes
    AlignedBytes bytes;              ///< count x record_bytes, 64-byte aligned

    uint64_t address(uint64_t index) const { return base + index * record_bytes; }
    uint64_t size_bytes() const { return count * record_bytes; }
    template <class T>
    const T* records() const { return reinterpret_cast<const T*>(bytes.data()); }
    template <class T>
    T* records() { return reinterpret_cast<T*>(bytes.data()); }
};

struct AccelImage {
    /// First region's address; regions follow at 4 GiB granules (docs/model.md, memory map).
    static constexpr uint64_t kBase = 1ull << 32;
    static constexpr uint64_t kGranule = 1ull << 32;

    std::string kind;                          ///< registry name ("bvh2", ...; accel_kinds())
    double build_ms = 0.0;                     ///< wall time of the build (not in the trace: traces are deterministic)
    nlohmann::json params = nlohmann::json::object();  ///< kind-specific, read by its stepper
    nlohmann::json stats = nlohmann::json::object();   ///< build statistics (manifest "accel")
    Aabb bounds;                               ///< of the whole scene
    /// A deque: a Region& from add_region() stays valid when later regions are added.
    std::deque<Region> regions;
    /// Build time only (not in the trace): the first triangle of every leaf, ascending, for
    /// structures whose leaves are contiguous runs of "triangles" (compressed leaves start a
    /// block at each; leaf_blocks.h). Empty for structures that fetch single triangles.
    std::vector<uint32_t> leaf_starts;

    /// Adds a region of `count` records of `record_bytes` in `layout`, zero-filled (zero = false:
    /// uninitialised, for a caller that writes every byte of every record); addresses are
    /// assigned by place_regions(). The reference stays valid when more regions are added.
    Region& add_region(const std::string& name, DataKind kind, uint32_t record_bytes, uint64_t count,
                       RecordLayout layout = {}, bool zero = true);
    /// Adds a region of records of type T, in T's declared layout (layout_of(const T*)).
    template <class T>
    Region& add_region(const std::string& name, DataKind kind, uint64_t count, bool zero = true) {
        return add_region(name, kind, uint32_t(sizeof(T)), count, layout_of(static_cast<const T*>(nullptr)), zero);
    }
    /// The region called `name`; throws rtsim::Error naming it (and the image's kind) if absent.
    const Region& region(const std::string& name) const;
    Region& region(const std::string& name);
    bool has_region(const std::string& name) const;
    /// Lays the regions out in order: the first at kBase, each next one at the following
    /// multiple of kGranule after the previous one's end.
    void place_regions();
    /// First address after the image (the model places rays, hits and stacks from here).
    uint64_t end_address() const;
    /// Bytes of all regions.
    uint64_t footprint_bytes() const;

    /// kind, params, stats, bounds and each region's name, kind, record size, count, base and
    /// record layout:
    /// what the trace's ACCL section holds besides the region payloads (docs/trace_format.md).
    nlohmann::json descriptor() const;
    /// Reads a descriptor back into an image whose regions are allocated but not filled.
    /// Throws rtsim::Error naming `source` and the field on anything malformed.
    static AccelImage from_descriptor(const nlohmann::json& d, const std::string& source);
};

/// Rounds up to a multiple of `granule` (a power of two).
inline uint64_t round_up(uint64_t x, uint64_t granule) { return (x + granule - 1) & ~(granule - 1); }

}  // namespace rtsim
