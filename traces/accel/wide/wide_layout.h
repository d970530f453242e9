#pragma once
// The fp32 wide BVH node, WideNode<N> for N = 4, 6, 8 (docs/accel.md, "bvh4, bvh6, bvh8"):
// the binary HwNode's per-axis layout (traces/bvh/hw_layout.h) widened to N children, so one
// 4-lane operation tests one plane of four children.
//
//   offset     bytes  field
//   0          24 N   bounds[3][2][N]: axis a at 8 N a bytes; its N minima, then its N maxima
//   24 N       4 N    child_ref[N]: interior child: node index; leaf: first triangle index
//   28 N       4 N    child_count[N]: 0 interior child; kEmptyChild empty slot; else leaf size
//   32 N              total: 128 (N = 4), 192 (N = 6), 256 (N = 8): 2, 3, 4 cache lines
//
// An empty slot holds the empty box (min +inf, max -inf, which the robust slab test can never
// hit: every near distance is +inf or every far distance -inf), child_ref 0 and count kEmptyChild.
// Empty slots are neither tested nor counted: a node step runs one box test per child.
#include <cstdint>

#include "traces/bvh/hw_layout.h"

namespace rtsim {

template <int N>
struct alignas(64) WideNode {
    static_assert(N >= 2 && N <= 8, "wide nodes hold 2 to 8 children");
    float bounds[3][2][N];
    uint32_t child_ref[N];
    uint32_t child_count[N];

    float lo(int slot, int axis) const { return bounds[axis][0][slot]; }
    float hi(int slot, int axis) const { return bounds[axis][1][slot]; }
    float& lo(int slot, int axis) { return bounds[axis][0][slot]; }
    float& hi(int slot, int axis) { return bounds[axis][1][slot]; }
};
static_assert(sizeof(WideNode<4>) == 128, "WideNode<4> must be 128 bytes");
static_assert(sizeof(WideNode<6>) == 192, "WideNode<6> must be 192 bytes");
static_assert(sizeof(WideNode<8>) == 256, "WideNode<8> must be 256 bytes");
template <int N>
RecordLayout layout_of(const WideNode<N>*) {
    return {RTSIM_FIELD(WideNode<N>, bounds), RTSIM_FIELD(WideNode<N>, child_ref), RTSIM_FIELD(WideNode<N>, child_count)};
}

}  // namespace rtsim
