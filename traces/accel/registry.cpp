// The registry of acceleration structures: each kind's builder and loader by name. Adding a
// structure adds its folder and one entry here (docs/accel.md, "Adding a structure").
#include <algorithm>
#include <chrono>
#include <functional>

#include "traces/accel/accel.h"
#include "traces/accel/bvh2/bvh2.h"
#include "traces/accel/cwbvh/cwbvh.h"
#include "traces/accel/grid/grid.h"
#include "traces/accel/two_level/two_level.h"
#include "traces/accel/wide/wide.h"
#include "traces/bvh/build_tree.h"
#include "traces/bvh/builder.h"
#include "traces/bvh/sbvh_builder.h"
#include "traces/common/error.h"
#include "traces/scene/scene.h"

namespace rtsim {

namespace {

using BuildFn = std::function<AccelImage(const Scene&, const AccelOptions&)>;
using LoadFn = std::function<std::unique_ptr<Accel>(AccelImage, const std::string&)>;

struct Entry {
    AccelKindInfo info;
    BuildFn build;
    LoadFn load;
};

/// The binary build tree of the chosen builder (the tree every BVH kind starts from): "binned"
/// (binned SAH) or "sbvh" (spatial splits; prim_ids may repeat a primitive). What the builder
/// reports beyond the tree's own statistics goes to `stats`.
BuildTree build_tree(const Scene& scene, const AccelOptions& o, nlohmann::json* stats) {
    if (o.builder != "sbvh") return build_binned_sah(scene.triangles, o.build, std::max(1u, o.build_threads));
    const SbvhConfig c;
    SbvhStats s;
    BuildTree tree = build_sbvh(scene.triangles, o.build, c, &s);
    (*stats)["sbvh"] = {{"config",
                         {{"alpha", c.alpha},
                          {"spatial_bins", c.spatial_bins},
                          {"reference_budget", c.reference_budget},
                          {"unsplit", c.unsplit}}},
                        {"references", s.references},
                        {"duplication", double(s.references) / double(scene.triangles.size())},
                        {"object_splits", s.object_splits},
                        {"spatial_splits", s.spatial_splits},
                        {"median_splits", s.median_splits},
                        {"unsplit_references", s.unsplit}};
    return tree;
}

AccelImage build_bvh2(const Scene& scene, const AccelOptions& o) {
    nlohmann::json extra = nlohmann::json::object();
    const BuildTree tree = build_tree(scene, o, &extra);
    AccelImage image = bvh2_image(tree, scene, o.build, o.builder);
    image.stats.update(extra);
    return image;
}

/// A wide BVH kind: the binary tree collapsed to `width` (wide.h), stored fp32 or compressed.
Entry wide_entry(const std::string& name, const std::string& description, int width, bool compressed,
                 ChildOrder order) {
    BuildFn build = [=](const Scene& scene, const AccelOptions& o) {
        nlohmann::json extra = nlohmann::json::object();
        const WideBuildTree wide = make_wide_tree(build_tree(scene, o, &extra), scene, width, o.build, order);
        AccelImage image = compressed ? cwbvh_image(wide, scene, name, order) : wide_image(wide, scene, name, order);
        image.stats = wide_stats(wide, o.build, o.builder, image.region("nodes").record_bytes, order);
        image.stats.update(extra);
        return image;
    };
    LoadFn load = [=](AccelImage image, const std::string& source) {
        return compressed ? load_cwbvh(std::move(image), width, source) : load_wide_fp32(std::move(image), width, source);
    };
    return {{name, description, {"binned", "sbvh"}}, build, load};
}

const std::vector<Entry>& registry() {
    static const std::vector<Entry> entries = {
        {{"bvh2", "binary BVH, 64-byte nodes holding both child boxes (docs/bvh_layout.md)", {"binned", "sbvh"}},
         build_bvh2,
         [](AccelImage image, const std::string& source) {
             return std::make_unique<Bvh2Accel>(std::move(image), source);
         }},
        wide_entry("bvh4", "4-wide BVH, 128-byte fp32 nodes, SAH-optimal collapse of the binary tree (docs/accel.md)", 4,
                   false, ChildOrder::distance),
        wide_entry("bvh6", "6-wide BVH, 192-byte fp32 nodes, SAH-optimal collapse", 6, false, ChildOrder::distance),
        wide_entry("bvh8", "8-wide BVH, 256-byte fp32 nodes, SAH-optimal collapse", 8, false, ChildOrder::distance),
        wide_entry("cwbvh6", "6-wide compressed BVH, 64-byte nodes with 8-bit quantised boxes (Intel Xe BVH6-like)", 6,
                   true, ChildOrder::distance),
        wide_entry("cwbvh8", "8-wide compressed BVH, 80-byte nodes with 8-bit quantised boxes (Ylitie et al. 2017)", 8,
                   true, ChildOrder::distance),
        wide_entry("bvh8_octant", "bvh8 with children in octant slots, visited in a fixed per-octant order (no sort)",
                   8, false, ChildOrder::octant),
        wide_entry("cwbvh8_octant", "cwbvh8 with children in octant slots, visited in a fixed per-octant order", 8,
                   true, ChildOrder::octant),
        {{"grid", "uniform grid, cells of lambda x N by density, 3D-DDA traversal, no stack (docs/accel.md)",
          {"uniform"}},
         [](const Scene& scene, const AccelOptions&) { return grid_image(scene); },
         [](AccelImage image, const std::string& source) {
             return std::make_unique<GridAccel>(std::move(image), source);
         }},
    };
    return entries;
}

const Entry* find(const std::string& kind) {
    for (const Entry& e : registry())
        if (e.info.name == kind) return &e;
    return nullptr;
}

std::string known_kinds() {
    std::string s;
    for (const Entry& e : registry()) s += (s.empty() ? "" : ", ") + e.info.name;
    return s;
}

}  // namespace

const std::vector<AccelKindInfo>& accel_kinds() {
    static const std::vector<AccelKindInfo> kinds = [] {
        std::vector<AccelKindInfo> v;
        for (const Entry& e : registry()) v.push_back(e.info);
        return v;
    }();
    return kinds;
}

void validate_accel_options(const AccelOptions& o) {
    const Entry* e = find(o.kind);
    require(e != nullptr, "accel: unknown structure '" + o.kind + "' (known: " + known_kinds() + ")");
    const auto& b = e->info.builders;
    if (o.builder.empty() || std::find(b.begin(), b.end(), o.builder) != b.end()) return;
    std::string list;
    for (const std::string& name : b) list += (list.empty() ? "" : ", ") + name;
    throw Error("accel: structure '" + o.kind + "' has no builder '" + o.builder + "' (it takes: " + list + ")");
}

AccelImage build_accel(const Scene& scene, const AccelOptions& options) {
    validate_accel_options(options);
    AccelOptions o = options;
    if (o.builder.empty()) o.builder = find(o.kind)->info.builders.front();  // the kind's default
    const auto start = std::chrono::steady_clock::now();
    if (o.two_level) {
        AccelImage image = build_two_level(scene, o);
        image.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        image.stats["footprint_bytes"] = image.footprint_bytes();
        return image;
    }
    require(!scene.triangles.empty(), "scene has no triangles");
    require(scene.tri_material.size() == scene.triangles.size() && scene.tri_instance.size() == scene.triangles.size(),
            "build_accel: scene is not flattened (call Scene::flatten())");
    AccelImage image = find(o.kind)->build(scene, o);
    image.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    image.stats["footprint_bytes"] = image.footprint_bytes();
    return image;
}

std::unique_ptr<Accel> load_accel(AccelImage image, const std::string& source) {
    if (image.kind == "two_level") return std::make_unique<TwoLevelAccel>(std::move(image), source);
    const Entry* e = find(image.kind);
    require(e != nullptr, source + ": unknown acceleration structure '" + image.kind + "' (this build knows: " +
                              known_kinds() + ")");
    return e->load(std::move(image), source);
}

}  // namespace rtsim
