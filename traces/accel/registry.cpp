// The registry of acceleration structures: each kind's builder and loader by name. Adding a
// structure adds its folder and one entry here (docs/accel.md, "Adding a structure").
#include <algorithm>
#include <chrono>
#include <functional>

#include "traces/accel/accel.h"
#include "traces/accel/bvh2/bvh2.h"
#include "traces/bvh/build_tree.h"
#include "traces/bvh/builder.h"
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

/// The binary build tree of the chosen builder (the tree every BVH kind starts from).
BuildTree build_tree(const Scene& scene, const AccelOptions& o) {
    return build_binned_sah(scene.triangles, o.build);
}

AccelImage build_bvh2(const Scene& scene, const AccelOptions& o) {
    const BuildTree tree = build_tree(scene, o);
    return bvh2_image(flatten_bvh(tree, scene, o.build), o.build, o.builder);
}

const std::vector<Entry>& registry() {
    static const std::vector<Entry> entries = {
        {{"bvh2", "binary BVH, 64-byte nodes holding both child boxes (docs/bvh_layout.md)", {"binned"}},
         build_bvh2,
         [](AccelImage image, const std::string& source) {
             return std::make_unique<Bvh2Accel>(std::move(image), source);
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
    if (std::find(b.begin(), b.end(), o.builder) != b.end()) return;
    std::string list;
    for (const std::string& name : b) list += (list.empty() ? "" : ", ") + name;
    throw Error("accel: structure '" + o.kind + "' has no builder '" + o.builder + "' (it takes: " + list + ")");
}

AccelImage build_accel(const Scene& scene, const AccelOptions& o) {
    validate_accel_options(o);
    require(!scene.triangles.empty(), "scene has no triangles");
    require(scene.tri_material.size() == scene.triangles.size() && scene.tri_instance.size() == scene.triangles.size(),
            "build_accel: scene is not flattened (call Scene::flatten())");
    const auto start = std::chrono::steady_clock::now();
    AccelImage image = find(o.kind)->build(scene, o);
    image.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    image.stats["footprint_bytes"] = image.footprint_bytes();
    return image;
}

std::unique_ptr<Accel> load_accel(AccelImage image, const std::string& source) {
    const Entry* e = find(image.kind);
    require(e != nullptr, source + ": unknown acceleration structure '" + image.kind + "' (this build knows: " +
                              known_kinds() + ")");
    return e->load(std::move(image), source);
}

}  // namespace rtsim
