#pragma once
// Operation kinds: what a traversal step asks the hardware to compute once its data has arrived.
// The model sends each to the pipeline configured for its kind (rtl_model/isect); the work
// counters name which kind's tests they count (work_counts.h). A structure that needs a new kind
// appends it here and adds one pipeline config (docs/accel.md, "Adding a structure").
#include <array>
#include <cstddef>
#include <cstdint>

namespace rtsim {

/// Values are stable (stats keys, per-kind arrays); append only.
enum class OpKind : uint8_t {
    box = 0,        ///< ray/box test
    triangle = 1,   ///< ray/triangle test
    anyhit = 2,     ///< alpha (any-hit) evaluation of a MASK triangle
    transform = 3,  ///< ray transform into an instance's object space
    cell = 4,       ///< 3D-DDA step to the next grid cell
    plane = 5,      ///< ray/split-plane test
    obb = 6,        ///< ray rotation into an oriented node's frame (its child boxes are tested there)
    sphere = 7,     ///< ray/sphere test (curved primitives)
    capsule = 8,    ///< ray/capsule test (curved primitives: a swept sphere)
};
constexpr int kOpKindCount = 9;
/// "No operation kind" in tables keyed by kind (a work counter that counts no pipeline's tests).
constexpr OpKind kNoOpKind = OpKind(0xFF);

inline constexpr std::array<const char*, kOpKindCount> kOpKindNames{
    {"box", "triangle", "anyhit", "transform", "cell", "plane", "obb", "sphere", "capsule"}};
/// "box", "triangle", ...; "unknown" outside the enum.
inline const char* op_kind_name(OpKind kind) {
    return size_t(kind) < kOpKindNames.size() ? kOpKindNames[size_t(kind)] : "unknown";
}

}  // namespace rtsim
