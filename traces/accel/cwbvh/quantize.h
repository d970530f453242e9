#pragma once
// Child boxes quantised to 8 bits against a per-node frame with power-of-two scales (Ylitie,
// Karras & Laine 2017, section 3.3): coordinate = p[a] + q * 2^(e[a] - 127), q in 0..255.
//
// Decoding is the float expression decode() below, in every stepper and every test. Encoding
// rounds outward against that very expression (lo: the largest q whose decoded value is <= the
// exact bound; hi: the smallest q whose decoded value is >= it), so a decoded box always contains
// the exact box. The robust slab test is monotone in the planes (IEEE subtraction and
// multiplication by a fixed value are monotone), so a ray that hits the exact box hits the
// decoded one, entering no later: quantisation adds box hits, never loses one, and hits stay
// bit-identical to the fp32 structures' (docs/accel.md, "Compressed wide BVHs").
#include <cstdint>
#include <cstring>

#include "traces/common/aabb.h"

namespace rtsim {

/// Scale 2^(e - 127) of an exponent byte e in 1..254 (a normal float with a zero mantissa).
inline float quant_scale(uint8_t e) {
    const uint32_t bits = uint32_t(e) << 23;
    float f;
    std::memcpy(&f, &bits, 4);
    return f;
}

/// The decoded coordinate of q: p + q * scale (q * scale is exact; the sum rounds once).
inline float quant_decode(float p, uint8_t e, uint32_t q) { return p + float(q) * quant_scale(e); }

/// A node's frame: origin p (the node box's lower corner) and per-axis exponent bytes, the
/// smallest for which q = 255 reaches the node box's upper bound.
struct QuantFrame {
    float p[3];
    uint8_t e[3];
};

QuantFrame make_quant_frame(const Aabb& node_box);
/// Largest q with quant_decode(q) <= lo (lo must be >= the frame's p).
uint8_t quantize_lo(const QuantFrame& f, int axis, float lo);
/// Smallest q with quant_decode(q) >= hi (hi must be within the frame's box).
uint8_t quantize_hi(const QuantFrame& f, int axis, float hi);
/// quantize_lo and quantize_hi of `count` (at most 8) bounds on one axis: q_lo[i] of lo[i],
/// q_hi[i] of hi[i]. The same bytes, several bounds per SIMD operation (a node's children).
void quantize_bounds(const QuantFrame& f, int axis, const float* lo, const float* hi, uint32_t count, uint8_t* q_lo,
                     uint8_t* q_hi);

}  // namespace rtsim
