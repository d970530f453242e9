// The registry of acceleration structures: each kind's builders, their settings, its build and
// load functions by name. Adding a structure adds its folder and one entry here (docs/accel.md,
// "Adding a structure").
#include <algorithm>
#include <chrono>
#include <functional>
#include <new>

#include "traces/accel/accel.h"
#include "traces/accel/bih/bih.h"
#include "traces/accel/bkd/bkd.h"
#include "traces/accel/build_settings.h"
#include "traces/accel/bvh2/bvh2.h"
#include "traces/accel/cwbvh/cwbvh.h"
#include "traces/accel/gkbvh/gkbvh.h"
#include "traces/accel/grid/grid.h"
#include "traces/accel/kdtree/kdtree.h"
#include "traces/accel/leaf_blocks.h"
#include "traces/accel/obvh/obvh.h"
#include "traces/accel/octree/octree.h"
#include "traces/accel/two_level/two_level.h"
#include "traces/accel/wide/wide.h"
#include "traces/bvh/build_tree.h"
#include "traces/bvh/builder.h"
#include "traces/bvh/lbvh_builder.h"
#include "traces/bvh/refit.h"
#include "traces/bvh/sbvh_builder.h"
#include "traces/bvh/sweep_builder.h"
#include "traces/common/error.h"
#include "traces/common/stopwatch.h"
#include "traces/scene/scene.h"

namespace rtsim {

namespace {

/// Every builder's documented Config: what the settings overrides apply to.
struct BuildSettings {
    BuildConfig bvh;
    SbvhConfig sbvh;
    LbvhConfig lbvh;
    GridConfig grid;
    KdConfig kd;
    BihConfig bih;
    OctreeConfig octree;
    GkConfig gk;
    ObbConfig obb;
    LeafConfig leaves;  ///< every kind's leaf layout (plain or compressed)
};

using SettingsFn = std::function<void(const std::string& builder, BuildSettings&, SettingsVisitor&)>;
using BuildFn = std::function<AccelImage(const Scene&, const AccelOptions&, const BuildSettings&)>;
using LoadFn = std::function<std::unique_ptr<Accel>(AccelImage, const std::string&)>;

struct Entry {
    AccelKindInfo info;  ///< its name, description, builders and capabilities (as data: capabilities.h)
    SettingsFn settings;
    BuildFn build;
    LoadFn load;
};

/// Binned SAH (Wald 2007).
BuildTree build_binned(const Scene& scene, const BuildSettings& s, unsigned threads, nlohmann::json*) {
    return build_binned_sah(scene.triangles, s.bvh, std::max(1u, threads));
}

/// Morton codes (Lauterbach et al. 2009).
BuildTree build_morton(const Scene& scene, const BuildSettings& s, unsigned, nlohmann::json*) {
    return build_lbvh(scene.triangles, s.bvh, s.lbvh);
}

/// Spatial splits (Stich et al. 2009): prim_ids may repeat a primitive; its statistics go to
/// the structure's stats.
BuildTree build_spatial_splits(const Scene& scene, const BuildSettings& s, unsigned, nlohmann::json* stats) {
    const SbvhConfig& c = s.sbvh;
    SbvhStats st;
    BuildTree tree = build_sbvh(scene.triangles, s.bvh, c, &st);
    (*stats)["sbvh"] = {{"config",
                         {{"alpha", c.alpha},
                          {"spatial_bins", c.spatial_bins},
                          {"reference_budget", c.reference_budget},
                          {"unsplit", c.unsplit}}},
                        {"references", st.references},
                        {"duplication", double(st.references) / double(scene.triangles.size())},
                        {"object_splits", st.object_splits},
                        {"spatial_splits", st.spatial_splits},
                        {"median_splits", st.median_splits},
                        {"unsplit_references", st.unsplit}};
    return tree;
}

/// One builder of binary build trees (the tree every BVH kind, and BIH's tree builders, start from).
struct TreeBuilder {
    const char* name;
    /// threads: the build's worker threads where the builder has them (the tree does not depend on them)
    BuildTree (*build)(const Scene&, const BuildSettings&, unsigned threads, nlohmann::json* stats);
    void (*settings)(BuildSettings&, SettingsVisitor&);  ///< its own settings beyond the SAH leaf rules
    bool sah_costs;                                     ///< it reads the SAH bins and costs
};

/// The tree builders by name: a kind's builders list names from here, and adding one is a line here.
const std::vector<TreeBuilder>& tree_builders() {
    static const std::vector<TreeBuilder> b = {
        {"binned", build_binned, [](BuildSettings&, SettingsVisitor&) {}, true},
        {"sbvh", build_spatial_splits, [](BuildSettings& s, SettingsVisitor& v) { s.sbvh.visit(v); }, true},
        {"lbvh", build_morton, [](BuildSettings& s, SettingsVisitor& v) { s.lbvh.visit(v); }, false},
        // Full sweeping-plane SAH and equal-count (median) splits (sweep_builder.h): no bins.
        {"sweep", [](const Scene& sc, const BuildSettings& s, unsigned, nlohmann::json*) { return build_sweep_sah(sc.triangles, s.bvh); },
         [](BuildSettings&, SettingsVisitor&) {}, false},
        // The full sweep with local ray termination in its split cost (sweep_builder.h).
        {"lrt", [](const Scene& sc, const BuildSettings& s, unsigned, nlohmann::json*) { return build_sweep_termination(sc.triangles, s.bvh); },
         [](BuildSettings&, SettingsVisitor&) {}, false},
        {"median", [](const Scene& sc, const BuildSettings& s, unsigned, nlohmann::json*) { return build_median(sc.triangles, s.bvh); },
         [](BuildSettings&, SettingsVisitor&) {}, false},
    };
    return b;
}

const TreeBuilder& tree_builder(const std::string& name) {
    for (const TreeBuilder& b : tree_builders())
        if (name == b.name) return b;
    throw Error("accel: no tree builder '" + name + "'");
}

std::vector<std::string> tree_builder_names() {
    std::vector<std::string> names;
    for (const TreeBuilder& b : tree_builders()) names.push_back(b.name);
    return names;
}

/// The settings of the chosen tree builder.
void tree_settings(const std::string& builder, BuildSettings& s, SettingsVisitor& v) {
    const TreeBuilder& b = tree_builder(builder);
    s.bvh.visit(v, b.sah_costs);
    b.settings(s, v);
}

/// The binary build tree of the chosen builder (on o.build_threads); what the builder reports
/// beyond the tree's own statistics goes to `stats`.
/// With o.tree_reuse: its refit_from refitted instead of a build, and the tree kept in its built.
BuildTree build_tree(const Scene& scene, const AccelOptions& o, const BuildSettings& s, nlohmann::json* stats) {
    TreeReuse* reuse = o.tree_reuse;
    BuildTree tree = reuse && reuse->refit_from ? refit_build_tree(*reuse->refit_from, scene.triangles)
                                                : tree_builder(o.builder).build(scene, s, o.build_threads, stats);
    if (reuse) reuse->built = std::make_shared<const BuildTree>(tree);
    return tree;
}

AccelImage build_bvh2(const Scene& scene, const AccelOptions& o, const BuildSettings& s) {
    nlohmann::json extra = nlohmann::json::object();
    const BuildTree tree = build_tree(scene, o, s, &extra);
    AccelImage image = bvh2_image(tree, scene, s.bvh, o.builder);
    image.stats.update(extra);
    return image;
}

/// A wide BVH kind: the binary tree collapsed to `width` (wide.h), stored fp32 or compressed.
Entry wide_entry(const std::string& name, const std::string& description, int width, bool compressed,
                 ChildOrder order) {
    BuildFn build = [=](const Scene& scene, const AccelOptions& o, const BuildSettings& s) {
        nlohmann::json extra = nlohmann::json::object();
        const WideBuildTree wide = make_wide_tree(build_tree(scene, o, s, &extra), scene, width, s.bvh, order);
        AccelImage image = compressed ? cwbvh_image(wide, scene, name, order) : wide_image(wide, scene, name, order);
        image.stats = wide_stats(wide, s.bvh, o.builder, image.region("nodes").record_bytes, order);
        // Compressed: costed with the boxes the hardware tests (dequantised outward, looser).
        if (compressed) {
            image.stats["sah_cost_exact_boxes"] = image.stats["sah_cost"];
            image.stats["sah_cost"] = cwbvh_sah_cost(image, s.bvh.traversal_cost, s.bvh.intersection_cost);
        }
        image.stats.update(extra);
        return image;
    };
    LoadFn load = [=](AccelImage image, const std::string& source) {
        // The kind fixes the child order its slots were assigned for: an image of the other
        // order under this name (relabelled) is refused, not walked in the wrong order.
        const ChildOrder given = child_order_param(image, source);
        require(given == order, source + ": " + name + " lays its children out in " + child_order_name(order) +
                                    " order, but the image's params.order is " + child_order_name(given) +
                                    " (an image of another kind under this name?)");
        return compressed ? load_cwbvh(std::move(image), width, source) : load_wide_fp32(std::move(image), width, source);
    };
    AccelCapabilities c = single_level(kBvhStackEntryBytes)
                              .with(&AccelCapabilities::packet_kernel)
                              .with(&AccelCapabilities::restart_trail)
                              .with(&AccelCapabilities::reduced_precision_boxes)
                              .with(&AccelCapabilities::refit)
                              .with(&AccelCapabilities::anyhit_order)
                              .with(&AccelCapabilities::stack_addresses)
                              .with(&AccelCapabilities::curved);
    c.quantized_boxes = compressed;
    return {{name, description, tree_builder_names(), c}, tree_settings, build, load};
}

template <class A>
LoadFn loader() {
    return [](AccelImage image, const std::string& source) { return std::make_unique<A>(std::move(image), source); };
}

const std::vector<Entry>& registry() {
    static const std::vector<Entry> entries = {
        {{"bvh2", "binary BVH, 64-byte nodes holding both child boxes (docs/bvh_layout.md)", tree_builder_names(),
          single_level(kBvhStackEntryBytes)
              .with(&AccelCapabilities::packet_kernel)
              .with(&AccelCapabilities::restart_trail)
              .with(&AccelCapabilities::reduced_precision_boxes)
              .with(&AccelCapabilities::anyhit_order)
              .with(&AccelCapabilities::refit)
              .with(&AccelCapabilities::stack_addresses)
              .with(&AccelCapabilities::curved)},
         tree_settings, build_bvh2, loader<Bvh2Accel>()},
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
          {"uniform"}, single_level(kBvhStackEntryBytes).with(&AccelCapabilities::packet_kernel).with(&AccelCapabilities::mailbox)},  // no stack: the machine's entry size is moot
         [](const std::string&, BuildSettings& s, SettingsVisitor& v) { s.grid.visit(v); },
         [](const Scene& scene, const AccelOptions&, const BuildSettings& s) { return grid_image(scene, s.grid); },
         loader<GridAccel>()},
        {{"kdtree", "kd-tree, SAH in O(N log N) with perfect splits (Wald & Havran 2006), 8-byte nodes, plane tests",
          {"sah"},
          single_level(kKdStackEntryBytes)
              .with(&AccelCapabilities::packet_kernel)
              .with(&AccelCapabilities::mailbox)
              .with(&AccelCapabilities::restart_trail)},
         [](const std::string&, BuildSettings& s, SettingsVisitor& v) { s.kd.visit(v); },
         [](const Scene& scene, const AccelOptions&, const BuildSettings& s) { return kdtree_image(scene, s.kd); },
         loader<KdAccel>()},
        {{"bih", "bounding interval hierarchy, two clip planes per 12-byte node, no duplicates (Wachter & Keller 2006)",
          {"binned", "wachter_keller", "lbvh", "sweep", "lrt", "median"},
          single_level(kBihStackEntryBytes)
              .with(&AccelCapabilities::packet_kernel)
              .with(&AccelCapabilities::restart_trail)
              .with(&AccelCapabilities::refit)
              .with(&AccelCapabilities::curved)},
         [](const std::string& builder, BuildSettings& s, SettingsVisitor& v) {
             if (builder == "wachter_keller") s.bih.visit(v);
             else tree_settings(builder, s, v);
         },
         [](const Scene& scene, const AccelOptions& o, const BuildSettings& s) {
             if (o.builder == "wachter_keller") return bih_image(build_bih(scene, s.bih), scene, o.builder);
             nlohmann::json unused;
             return bih_image(bih_from_build_tree(build_tree(scene, o, s, &unused)), scene, o.builder);
         },
         loader<BihAccel>()},
        {{"gkbvh", "GK-BVH: a binary BVH by space subdivision alone, straddlers referenced on both sides (Popov et al. 2009)",
          {"clipped", "boxes"}, single_level(kBvhStackEntryBytes)
                                    .with(&AccelCapabilities::packet_kernel)
                                    .with(&AccelCapabilities::anyhit_order)
                                    .with(&AccelCapabilities::restart_trail)
                                    .with(&AccelCapabilities::reduced_precision_boxes)
                                    .with(&AccelCapabilities::stack_addresses)},
         [](const std::string& builder, BuildSettings& s, SettingsVisitor& v) {
             s.bvh.visit(v, false);
             s.gk.visit(v, builder == "clipped");
         },
         [](const Scene& scene, const AccelOptions& o, const BuildSettings& s) { return gkbvh_image(scene, o.builder, s.bvh, s.gk); },
         loader<Bvh2Accel>()},
        {{"obvh2", "binary BVH whose nodes may hold their child boxes in a rotated frame (oriented boxes, as RDNA 4)",
          tree_builder_names(),
          single_level(kBvhStackEntryBytes)
              .with(&AccelCapabilities::packet_kernel)
              .with(&AccelCapabilities::restart_trail)
              .with(&AccelCapabilities::reduced_precision_boxes)
              .with(&AccelCapabilities::anyhit_order)
              .with(&AccelCapabilities::stack_addresses)
              .with(&AccelCapabilities::curved)},
         [](const std::string& builder, BuildSettings& s, SettingsVisitor& v) {
             tree_settings(builder, s, v);
             s.obb.visit(v);
         },
         [](const Scene& scene, const AccelOptions& o, const BuildSettings& s) {
             nlohmann::json extra = nlohmann::json::object();
             // A refit may keep the rotations of the image it refits (TreeReuse::rotations).
             TreeReuse* reuse = o.tree_reuse;
             const bool keep = s.obb.refit_keeps_rotations && reuse && reuse->refit_from && reuse->rotations;
             const std::shared_ptr<const std::vector<uint8_t>> kept = keep ? reuse->rotations : nullptr;
             const BuildTree tree = build_tree(scene, o, s, &extra);
             AccelImage image =
                 obvh2_image(tree, scene, s.bvh, s.obb, o.builder, std::max(1u, o.build_threads), kept.get());
             image.stats.update(extra);
             if (reuse) {
                 reuse->rotations = std::make_shared<const std::vector<uint8_t>>(obvh2_rotations(image));
                 reuse->image_sah_cost = image.stats["sah_cost"].get<double>();  // the oriented boxes'
             }
             return image;
         },
         loader<ObvhAccel>()},
        {{"bkd", "B-Kd tree: two intervals per 20-byte node on one axis, no duplicates (Woop et al. 2006)",
          tree_builder_names(),
          single_level(kBkdStackEntryBytes)
              .with(&AccelCapabilities::packet_kernel)
              .with(&AccelCapabilities::refit)
              .with(&AccelCapabilities::curved)},
         tree_settings,
         [](const Scene& scene, const AccelOptions& o, const BuildSettings& s) {
             nlohmann::json unused;
             return bkd_image(bkd_from_build_tree(build_tree(scene, o, s, &unused)), scene, o.builder);
         },
         loader<BkdAccel>()},
        {{"octree", "adaptive octree, 16-byte nodes, parametric traversal (Revelles et al. 2000)", {"adaptive"},
          single_level(kOctStackEntryBytes).with(&AccelCapabilities::packet_kernel).with(&AccelCapabilities::mailbox)},
         [](const std::string&, BuildSettings& s, SettingsVisitor& v) { s.octree.visit(v); },
         [](const Scene& scene, const AccelOptions&, const BuildSettings& s) { return octree_image(scene, s.octree); },
         loader<OctreeAccel>()},
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

/// The settings one (kind, builder) takes: its builder's, then the leaf layout every kind shares.
void kind_settings(const Entry& e, const std::string& builder, BuildSettings& s, SettingsVisitor& v) {
    e.settings(builder, s, v);
    s.leaves.visit(v);
}

/// The entry and resolved builder of valid options.
const Entry& entry_of(const AccelOptions& o, std::string* builder) {
    validate_accel_options(o);
    const Entry& e = *find(o.kind);
    *builder = o.builder.empty() ? e.info.builders.front() : o.builder;  // empty: the kind's default
    return e;
}

/// The settings of (kind, builder) over `o.build`, with o.settings applied.
BuildSettings resolve_settings(const Entry& e, const std::string& builder, const AccelOptions& o, nlohmann::json* values) {
    BuildSettings s;
    s.bvh = o.build;
    const SettingsVisit visit = [&](SettingsVisitor& v) { kind_settings(e, builder, s, v); };
    apply_settings(visit, o.settings, "accel " + o.kind + " (builder " + builder + ")");
    if (values) *values = settings_values(visit);
    return s;
}

/// Refuses (naming the scene, the structure and what would trace it) a scene with curved
/// primitives on a structure, builder or leaf layout that cannot store them: splits that clip
/// primitives against planes and compressed leaf blocks (vertex indices). Two levels store them in
/// their BLASes (each BLAS kind's own capability).
void check_curved_supported(const Scene& scene, const Entry& e, const AccelOptions& o, const BuildSettings& s) {
    if (!scene.has_curved()) return;
    const std::string where = (scene.source.empty() ? std::string("scene") : scene.source) + ": the scene has curved primitives (spheres or capsules)";
    std::string kinds;
    for (const Entry& k : registry())
        if (k.info.capabilities.curved) kinds += (kinds.empty() ? "" : ", ") + k.info.name;
    require(e.info.capabilities.curved, where + ", which accel " + o.kind +
                                             " cannot store (its builder clips primitives against planes, or its "
                                             "leaves hold triangles only); trace it with one of: " + kinds);
    require(o.builder != "sbvh", where + ": the sbvh builder clips triangles against split planes; use binned, sweep, median or lbvh");
    require(!s.leaves.compressed, where + ": compressed leaves index triangle vertices; set leaves.compressed=false");
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

AccelCapabilities accel_capabilities(const std::string& kind, const std::string& blas_kind) {
    if (kind != "two_level") {
        const Entry* e = find(kind);
        require(e != nullptr, "accel: unknown structure '" + kind + "' (known: " + known_kinds() + ", two_level)");
        return e->info.capabilities;
    }
    // A TLAS over BLASes of one kind: one stack holds the TLAS's entries and the BLAS kind's;
    // packets walk the TLAS together and each BLAS with its kind's packet kernel (two_level.h).
    const AccelCapabilities blas = accel_capabilities(blas_kind);
    AccelCapabilities c;
    c.mailbox = blas.mailbox;
    c.packet_kernel = blas.packet_kernel;
    // Per-level restart trails, the BLASes' reduced-precision walks and compressed leaves (each
    // BLAS's leaf blocks a slice of "blas_leaf_blocks", decoded by its own load; two_level.h).
    c.restart_trail = blas.restart_trail;
    // The TLAS is a binary BVH: any-hit rays take the order at its nodes and at the BLAS's.
    c.anyhit_order = blas.anyhit_order;
    c.reduced_precision_boxes = blas.reduced_precision_boxes;
    // The BLASes' quantised box tests (the TLAS's boxes stay fp32), and stack addresses: the
    // TLAS's entries are node and instance-record addresses, the BLAS kind's its own.
    c.quantized_boxes = blas.quantized_boxes;
    c.stack_addresses = blas.stack_addresses;
    c.compressed_leaves = blas.compressed_leaves;
    c.treelet_partition = blas.treelet_partition;
    c.stack_entry_bytes = std::max(kBvhStackEntryBytes, blas.stack_entry_bytes);
    return c;
}

std::vector<StructureAlternative> structure_alternatives(const std::string& kind, bool compressed_leaves,
                                                         bool curved) {
    std::vector<StructureAlternative> out;
    if (kind.rfind("cwbvh", 0) == 0 || kind == "two_level") return out;
    if (kind == "bvh6") out.push_back({"accel", "cwbvh6"});
    else if (kind == "bvh8") out.push_back({"accel", "cwbvh8"});
    else out.insert(out.end(), {{"accel", "bvh8"}, {"accel", "cwbvh8"}});
    if (!compressed_leaves && !curved && accel_capabilities(kind).compressed_leaves)
        out.push_back({"compressed_leaves", "true"});
    return out;
}

std::string structure_alternative_dir(const StructureAlternative& a) {
    return "alternatives/" + a.key + "=" + a.value;
}

nlohmann::json accel_settings_schema(const std::string& kind, const std::string& builder) {
    AccelOptions o;
    o.kind = kind;
    o.builder = builder;
    std::string b;
    const Entry& e = entry_of(o, &b);
    BuildSettings s;
    return settings_schema([&](SettingsVisitor& v) { kind_settings(e, b, s, v); });
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
    AccelOptions o = options;
    const Entry& e = entry_of(options, &o.builder);
    nlohmann::json values;
    const BuildSettings s = resolve_settings(e, o.builder, o, &values);  // refuses bad settings before any work
    const auto start = std::chrono::steady_clock::now();
    auto finish = [&](AccelImage image) {
        // Two levels: each BLAS compressed its own leaves as it was built (two_level_build.cpp).
        if (s.leaves.compressed && !o.two_level) compress_leaves(image, image.leaf_starts, s.leaves);
        image.leaf_starts.clear();
        image.build_ms = ms_since(start);
        image.stats["footprint_bytes"] = image.footprint_bytes();
        // The TLAS's entries and the BLAS kind's share one stack: the larger size (two_level.h).
        image.stats["stack_entry_bytes"] =
            accel_capabilities(o.two_level ? "two_level" : o.kind, o.kind).stack_entry_bytes;
        image.stats["build_settings"] = values;
        image.stats["build_set"] = o.settings;
        return image;
    };
    check_curved_supported(scene, e, o, s);
    if (o.two_level) return finish(build_two_level(scene, o));
    require(!scene.triangles.empty(), "scene has no triangles");
    require(scene.tri_material.size() == scene.triangles.size() && scene.tri_instance.size() == scene.triangles.size(),
            "build_accel: scene is not flattened (call Scene::flatten())");
    AccelOptions resolved = o;
    resolved.build = s.bvh;
    // Each builder bounds its own work and memory before allocating (build_budget.h) and names
    // its settings; the refusal names the scene file too. An allocation that still fails is
    // reported the same way, not as a bare std::bad_alloc.
    const std::string where = scene.source.empty() ? std::string("scene") : scene.source;
    if (o.tree_reuse) o.tree_reuse->built.reset();  // set again by the build, if it makes a tree
    try {
        AccelImage image = e.build(scene, resolved, s);
        // A kind (or builder) that makes no binary tree cannot refit: refused, not rebuilt unseen.
        require(!o.tree_reuse || !o.tree_reuse->refit_from || o.tree_reuse->built,
                "accel " + o.kind + " (builder " + o.builder + ") is not built from a binary tree, so it cannot be "
                "refitted to moved geometry; use --frame-policy rebuild, or a kind that refits (bvh2, bvh4-8, "
                "cwbvh6/8, bih, bkd)");
        return finish(std::move(image));
    } catch (const Error& err) {
        const std::string what = err.what();
        if (what.rfind(where, 0) == 0) throw;
        throw Error(where + ": accel " + o.kind + " (builder " + o.builder + "): " + what);
    } catch (const std::bad_alloc&) {
        throw Error(where + ": accel " + o.kind + " (builder " + o.builder + ", settings " + values.dump() +
                    "): out of memory while building; lower the settings that multiply nodes, cells or references");
    }
}

std::unique_ptr<Accel> load_accel(AccelImage image, const std::string& source) {
    try {
        if (image.kind == "two_level") return std::make_unique<TwoLevelAccel>(std::move(image), source);
        const Entry* e = find(image.kind);
        require(e != nullptr, source + ": unknown acceleration structure '" + image.kind + "' (this build knows: " +
                                  known_kinds() + ")");
        return e->load(std::move(image), source);
    } catch (const Error& err) {
        // Every refusal names the trace, also those raised below the structures' own checks
        // (a region the image lacks).
        const std::string what = err.what();
        if (what.rfind(source, 0) == 0) throw;
        throw Error(source + ": " + what);
    }
}

}  // namespace rtsim
