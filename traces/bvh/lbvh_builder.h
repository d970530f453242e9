#pragma once
// LBVH: a BVH from Morton codes (Lauterbach, Garland, Sengupta, Luebke & Manocha 2009, "Fast BVH
// construction on GPUs", Eurographics), the fast end of the build-time/trace-cost trade-off. Each
// triangle's box centre is quantised to `morton_bits` per axis within the centroids' bounds and
// the bits interleaved (x highest); the codes are sorted, and a node's range is split where the
// highest bit in which its first and last codes differ changes (the binary radix tree of Karras
// 2012, "Maximizing parallelism in the construction of BVHs, octrees, and k-d trees", built top
// down here on one thread). Ranges of equal codes, and ranges near max_depth, split at the median.
// No SAH is evaluated: the build is a sort and linear passes.
#include <cstdint>
#include <vector>

#include "traces/bvh/build_tree.h"

namespace rtsim {

struct LbvhConfig {
    /// Morton bits per axis (3 x bits <= 63). More separate close centroids in large scenes; fewer
    /// make more equal codes (median splits).
    uint32_t morton_bits = 10;

    /// The settings as data (traces/accel/build_settings.h).
    template <class V>
    void visit(V& v) {
        v.field("morton_bits", morton_bits, "bits/axis", "Morton code bits per axis (the paper's 10: 30-bit codes)", 1, 21);
    }
};

/// Builds an LBVH over the triangles: leaves of at most config.max_leaf_size (the SAH constants
/// only price the tree afterwards). Throws rtsim::Error on a non-finite vertex or no triangles.
BuildTree build_lbvh(const std::vector<Triangle>& triangles, const BuildConfig& config, const LbvhConfig& lbvh = {});

}  // namespace rtsim
