#pragma once
// The byte layout of a record the trace stores (a ray, a hit, a BVH node, a triangle, ...),
// declared beside the record's struct with RTSIM_FIELD so offsets, element types and array
// shapes come from the compiler, not from a second hand-typed copy. The trace carries each image
// region's layout in its ACCL descriptor and the Python bindings expose the sections' layouts,
// so numpy reads every record with the C++ layout (python/rtsim/trace_file.py) and a new
// structure's regions need no Python change.
//
//   inline RecordLayout layout_of(const HwNode*) {
//       return {RTSIM_FIELD(HwNode, bounds), RTSIM_FIELD(HwNode, child_ref), ...};
//   }
#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

#include <nlohmann/json.hpp>

namespace rtsim {

struct FieldLayout {
    std::string name;             ///< "" for a record that is one scalar (a primitive reference)
    std::string type;             ///< numpy type string of one element: "<f4", "<u4", "<i4", "<u2", "u1", "<u8"
    uint32_t offset = 0;          ///< bytes from the record's start
    std::vector<uint32_t> shape;  ///< array extents, outermost first; empty for a scalar
    uint32_t element_bytes = 0;

    uint32_t bytes() const;
};
using RecordLayout = std::vector<FieldLayout>;

template <class T>
constexpr const char* element_type() {
    if constexpr (std::is_same_v<T, float>) return "<f4";
    else if constexpr (std::is_same_v<T, double>) return "<f8";
    else if constexpr (std::is_same_v<T, uint8_t>) return "u1";
    else if constexpr (std::is_same_v<T, uint16_t>) return "<u2";
    else if constexpr (std::is_same_v<T, uint32_t>) return "<u4";
    else if constexpr (std::is_same_v<T, int32_t>) return "<i4";
    else if constexpr (std::is_same_v<T, uint64_t>) return "<u8";
    else if constexpr (std::is_same_v<T, int64_t>) return "<i8";
    else static_assert(sizeof(T) == 0, "no layout type for this field's element type");
}

/// A field of type F (a scalar or a C array of scalars) at `offset`.
template <class F>
FieldLayout field_layout(const char* name, size_t offset) {
    FieldLayout f;
    f.name = name;
    f.offset = uint32_t(offset);
    using E = std::remove_all_extents_t<F>;
    f.type = element_type<E>();
    f.element_bytes = uint32_t(sizeof(E));
    if constexpr (std::rank_v<F> >= 1) f.shape.push_back(uint32_t(std::extent_v<F, 0>));
    if constexpr (std::rank_v<F> >= 2) f.shape.push_back(uint32_t(std::extent_v<F, 1>));
    if constexpr (std::rank_v<F> >= 3) f.shape.push_back(uint32_t(std::extent_v<F, 2>));
    static_assert(std::rank_v<F> <= 3, "fields of at most three array dimensions");
    return f;
}

#define RTSIM_FIELD(T, member) ::rtsim::field_layout<decltype(T::member)>(#member, offsetof(T, member))

/// A record that is one scalar of type T (a region of indices).
template <class T>
RecordLayout scalar_layout() {
    return {field_layout<T>("", 0)};
}

/// A region of 32-bit indices (primitive references): one unnamed scalar each.
inline RecordLayout layout_of(const uint32_t*) { return scalar_layout<uint32_t>(); }

/// [{name, type, offset, shape}, ...]: the form the ACCL descriptor and the bindings carry.
nlohmann::json layout_json(const RecordLayout& layout);
/// Reads layout_json's form back; throws rtsim::Error naming `source` on anything malformed.
RecordLayout layout_from_json(const nlohmann::json& j, const std::string& source);
/// Bytes the fields cover, each counted once; a layout of a struct of `record_bytes` that
/// covers fewer left a field out (tested for every declared layout).
uint32_t covered_bytes(const RecordLayout& layout, uint32_t record_bytes);

}  // namespace rtsim
