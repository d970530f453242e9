#pragma once
// Wide BVHs (docs/accel.md, "Wide BVHs"): the binary build tree of any builder, oversized leaves
// split, collapsed into N-wide nodes (wide_tree.h), serialised as fp32 WideNode<N>
// (wide_layout.h) or as compressed nodes (traces/accel/cwbvh/), traversed by one stepper.
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "traces/accel/wide/wide_accel.h"
#include "traces/accel/wide/wide_tree.h"
#include "traces/scene/scene.h"

namespace rtsim {

/// The wide tree of a kind: split leaves above min(kWideLeafMax, config.max_leaf_size), collapse
/// (SAH-optimal DP unless told otherwise), octant slots when `order` is octant.
WideBuildTree make_wide_tree(const BuildTree& tree, const Scene& scene, int width, const BuildConfig& config,
                             ChildOrder order, Collapse method = Collapse::dp);
/// The same from a tree the caller no longer needs (its leaves are split in place).
WideBuildTree make_wide_tree(BuildTree&& tree, const Scene& scene, int width, const BuildConfig& config,
                             ChildOrder order, Collapse method = Collapse::dp);

/// The fp32 image (kind `kind`, e.g. "bvh8") of a wide tree of width N = tree.width.
AccelImage wide_image(const WideBuildTree& tree, const Scene& scene, const std::string& kind, ChildOrder order);

/// Build statistics every wide kind records (manifest "accel"): builder and its config, width,
/// node and triangle bytes, nodes, leaves, depth, leaf sizes, SAH cost, collapse, order.
nlohmann::json wide_stats(const WideBuildTree& tree, const BuildConfig& config, const std::string& builder,
                          uint32_t node_bytes, ChildOrder order);

/// The Accel of an fp32 wide image of width `width` (4, 6 or 8).
std::unique_ptr<Accel> load_wide_fp32(AccelImage image, int width, const std::string& source);

const char* child_order_name(ChildOrder order);

}  // namespace rtsim
