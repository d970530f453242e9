// Building a two-level image (two_level.h): one BLAS per used mesh in object space, the TLAS a
// binned-SAH binary BVH over the instances' world boxes with one instance per leaf.
#include <cmath>
#include <cstring>
#include <algorithm>
#include <chrono>
#include <limits>
#include <numeric>
#include <optional>
#include <functional>
#include <unordered_map>

#include "traces/accel/two_level/two_level.h"
#include "traces/bvh/build_tree.h"
#include "traces/bvh/refit.h"
#include "traces/common/error.h"
#include "traces/common/stopwatch.h"
#include "traces/scene/scene.h"

namespace rtsim {

using nlohmann::json;

namespace {

/// What a triangle's BLAS record depends on besides its vertices: its alpha test.
int64_t alpha_key(const Scene& scene, uint32_t material) {
    const Material& m = scene.materials[material];
    return m.alpha_mode == AlphaMode::mask ? int64_t(std::lround(m.alpha_coverage * 255.0f)) : -1;
}

bool same_floats(const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
}

bool same_geometry(const Scene& scene, const Mesh& a, const Mesh& b) {
    if (a.positions.size() != b.positions.size() ||
        std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(Vec3)) != 0)
        return false;
    // Spheres and capsules: the same centres or ends and the same radii.
    if (!same_floats(a.radii, b.radii) || !same_floats(a.end_radii, b.end_radii)) return false;
    for (size_t t = 0; t < a.materials.size(); ++t)
        if (alpha_key(scene, a.materials[t]) != alpha_key(scene, b.materials[t])) return false;
    return true;
}

uint64_t geometry_hash(const Mesh& m) {
    uint64_t h = 0xcbf29ce484222325ull;  // FNV-1a over the vertex bytes
    const auto* p = reinterpret_cast<const unsigned char*>(m.positions.data());
    for (size_t i = 0; i < m.positions.size() * sizeof(Vec3); ++i) h = (h ^ p[i]) * 0x100000001b3ull;
    return h;
}

}  // namespace

std::vector<uint32_t> geometry_classes(const Scene& scene) {
    std::vector<uint32_t> cls(scene.meshes.size());
    std::unordered_map<uint64_t, std::vector<uint32_t>> seen;  // hash -> representatives
    for (uint32_t m = 0; m < scene.meshes.size(); ++m) {
        cls[m] = m;
        std::vector<uint32_t>& reps = seen[geometry_hash(scene.meshes[m])];
        for (uint32_t r : reps)
            if (same_geometry(scene, scene.meshes[r], scene.meshes[m])) {
                cls[m] = r;
                break;
            }
        if (cls[m] == m) reps.push_back(m);
    }
    return cls;
}

bool shares_geometry(const Scene& scene) {
    const std::vector<uint32_t> cls = geometry_classes(scene);
    std::vector<uint32_t> uses(scene.meshes.size(), 0);
    for (const Instance& inst : scene.instances)
        if (inst.mesh < cls.size() && scene.meshes[inst.mesh].triangle_count() && ++uses[cls[inst.mesh]] > 1)
            return true;
    return false;
}

namespace {

/// The mesh alone, in object space, as a flattened one-instance scene (local primitive ids).
Scene mesh_scene(const Scene& scene, uint32_t mesh) {
    Scene s;
    s.source = scene.source + ": mesh " + std::to_string(mesh) + " '" + scene.meshes[mesh].name + "'";
    s.meshes = {scene.meshes[mesh]};
    s.instances = {Instance{0, glm::dmat4(1.0), 0, -1}};
    s.materials = scene.materials;
    s.flatten();
    return s;
}

/// World box of an object box under `m`: the eight corners in double, padded by 2^-20 of the
/// box's magnitude and rounded outward to float, so the box holds every world point of the
/// instance's triangles and the object-space ray's hits despite the once-rounded transforms.
Aabb world_box(const Aabb& object, const glm::dmat4& m) {
    glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
    for (int c = 0; c < 8; ++c) {
        const glm::dvec4 p(c & 1 ? object.hi.x : object.lo.x, c & 2 ? object.hi.y : object.lo.y,
                           c & 4 ? object.hi.z : object.lo.z, 1.0);
        const glm::dvec3 w = glm::dvec3(m * p);
        lo = glm::min(lo, w);
        hi = glm::max(hi, w);
    }
    double magnitude = 0.0;
    for (int a = 0; a < 3; ++a) magnitude = std::max({magnitude, std::fabs(lo[a]), std::fabs(hi[a])});
    const double pad = std::ldexp(magnitude, -20);
    Aabb box;
    for (int a = 0; a < 3; ++a) {
        box.lo[a] = std::nextafter(float(lo[a] - pad), -std::numeric_limits<float>::infinity());
        box.hi[a] = std::nextafter(float(hi[a] + pad), std::numeric_limits<float>::infinity());
    }
    return box;
}

json bounds_json(const Aabb& b) {
    return {{"lo", {b.lo.x, b.lo.y, b.lo.z}}, {"hi", {b.hi.x, b.hi.y, b.hi.z}}};
}

/// The TLAS's build input: each instance box as a triangle with the box's bounds and centroid.
Scene box_scene(const std::vector<Aabb>& boxes) {
    Scene s;
    s.materials = {Material{}};
    for (size_t i = 0; i < boxes.size(); ++i) {
        const Aabb& b = boxes[i];
        s.triangles.push_back(Triangle{b.lo, b.hi, 0.5f * (b.lo + b.hi)});
        s.tri_material.push_back(0);
        s.tri_instance.push_back(uint32_t(i));
    }
    return s;
}

}  // namespace

namespace {

/// For each mesh, the mesh whose BLAS it uses: geometry_classes(), except that a deforming mesh
/// has a BLAS of its own (its vertices move each frame) and no other mesh shares it.
std::vector<uint32_t> blas_classes(const Scene& scene, const std::vector<bool>& deforming) {
    std::vector<uint32_t> cls = geometry_classes(scene);
    std::vector<int64_t> moved(scene.meshes.size(), -1);  // a static class whose representative deforms
    for (uint32_t m = 0; m < cls.size(); ++m) {
        if (deforming[m]) {
            cls[m] = m;
            continue;
        }
        if (!deforming[cls[m]]) continue;
        if (moved[cls[m]] < 0) moved[cls[m]] = m;
        cls[m] = uint32_t(moved[cls[m]]);
    }
    return cls;
}

/// The BLASes of a scene: one per geometry some instance places, and which instances place one.
struct BlasSet {
    std::vector<AccelImage> images;
    std::vector<uint32_t> blas_of_mesh;  ///< per mesh (meaningful for placed meshes)
    std::vector<uint32_t> placed;        ///< instances with geometry, scene order
};

/// `reuse_of(mesh)`: the tree reuse for a deforming mesh's build (null for static meshes).
BlasSet build_blases(const Scene& scene, const AccelOptions& options, const std::vector<uint32_t>& cls,
                     const std::function<TreeReuse*(uint32_t)>& reuse_of) {
    // Meshes without triangles are skipped; meshes of equal vertices and alpha tests share one
    // BLAS, whatever their materials.
    std::vector<int32_t> blas_of_class(scene.meshes.size(), -1);
    AccelOptions blas_options = options;
    blas_options.two_level = false;
    BlasSet set;
    set.blas_of_mesh.assign(scene.meshes.size(), 0);
    for (uint32_t i = 0; i < scene.instances.size(); ++i) {
        const uint32_t mesh = scene.instances[i].mesh;
        require(mesh < scene.meshes.size(), scene.source + ": instance " + std::to_string(i) + " has no mesh");
        if (scene.meshes[mesh].triangle_count() == 0) continue;
        if (blas_of_class[cls[mesh]] < 0) {
            blas_of_class[cls[mesh]] = int32_t(set.images.size());
            blas_options.tree_reuse = reuse_of(cls[mesh]);
            set.images.push_back(build_accel(mesh_scene(scene, cls[mesh]), blas_options));
        }
        set.blas_of_mesh[mesh] = uint32_t(blas_of_class[cls[mesh]]);
        set.placed.push_back(i);
    }
    require(!set.placed.empty(), scene.source + ": the scene has no triangles");
    return set;
}

/// One frame's TLAS and instance records (in TLAS leaf order) over the instances posed by `pose`.
struct TlasFrame {
    HwBvh tlas;
    std::vector<InstanceRecord> records;
    Aabb bounds;
};

/// `blas_of_mesh`: the frame's BLAS of each mesh; `reuse`: the TLAS's tree to refit and keep
/// (frame_policy.h), or null to build afresh.
TlasFrame build_tlas(const Scene& scene, const BlasSet& blases, const std::vector<uint32_t>& blas_of_mesh,
                     const std::vector<glm::dmat4>& pose, const AccelOptions& options, TreeReuse* reuse) {
    TlasFrame out;
    std::vector<Aabb> boxes(blases.placed.size());
    for (size_t k = 0; k < blases.placed.size(); ++k) {
        const uint32_t id = blases.placed[k];
        boxes[k] = world_box(blases.images[blas_of_mesh[scene.instances[id].mesh]].bounds, pose[id]);
        out.bounds.grow(boxes[k]);
    }
    BuildConfig tlas_config = options.build;
    tlas_config.max_leaf_size = 1;
    const Scene tlas_input = box_scene(boxes);
    // A box's "triangle" (lo, hi, centre) has the box as its bounds: a refit over them refits
    // the TLAS to the instances' new boxes.
    BuildTree tree = reuse && reuse->refit_from ? refit_build_tree(*reuse->refit_from, tlas_input.triangles)
                                                : build_binned_sah(tlas_input.triangles, tlas_config);
    out.tlas = flatten_bvh(tree, tlas_input, tlas_config);
    if (reuse) reuse->built = std::make_shared<const BuildTree>(std::move(tree));
    out.records.resize(blases.placed.size());
    for (size_t k = 0; k < blases.placed.size(); ++k) {
        const uint32_t id = blases.placed[out.tlas.triangles[k].prim];
        const Instance& inst = scene.instances[id];
        InstanceRecord& rec = out.records[k];
        store_affine_rows(glm::inverse(pose[id]), rec.world_to_object);
        store_affine_rows(pose[id], rec.object_to_world);
        rec.blas = blas_of_mesh[inst.mesh];
        rec.prim_base = inst.prim_base;
        rec.instance = id;
    }
    return out;
}

/// Appends the BLASes' regions to `image`, concatenated per name (each BLAS on a 64-byte
/// boundary); returns the params' "blas" list and adds the BLAS bytes to *bytes.
json add_blas_regions(AccelImage& image, const std::vector<AccelImage>& blases, uint64_t* bytes) {
    json blas_list = json::array();
    for (const AccelImage& b : blases) blas_list.push_back({{"params", b.params}, {"bounds", bounds_json(b.bounds)},
                                                            {"first", json::object()}, {"count", json::object()}});
    for (const Region& proto : blases[0].regions) {
        std::vector<uint64_t> first(blases.size());
        uint64_t total = 0;
        const uint64_t rb = proto.record_bytes, step = 64 / std::gcd(rb, uint64_t(64));
        for (size_t b = 0; b < blases.size(); ++b) {
            const Region& r = blases[b].region(proto.name);
            require(r.record_bytes == rb && r.kind == proto.kind, "two_level: BLAS regions '" + proto.name + "' differ");
            first[b] = round_up(total, step);
            total = first[b] + r.count;
            blas_list[b]["first"][proto.name] = first[b];
            blas_list[b]["count"][proto.name] = r.count;
        }
        Region& out = image.add_region("blas_" + proto.name, proto.kind, uint32_t(rb), total, proto.layout);
        for (size_t b = 0; b < blases.size(); ++b) {
            const Region& r = blases[b].region(proto.name);
            std::memcpy(out.bytes.data() + first[b] * rb, r.bytes.data(), r.size_bytes());
        }
        *bytes += out.size_bytes();
    }
    return blas_list;
}

}  // namespace

AccelImage build_two_level(const Scene& scene, const AccelOptions& options) {
    std::vector<glm::dmat4> pose;
    for (const Instance& inst : scene.instances) pose.push_back(inst.object_to_world);
    return build_two_level_frames(scene, options, {pose}, nullptr);
}

AccelImage build_two_level_frames(const Scene& scene, const AccelOptions& options,
                                  const std::vector<std::vector<glm::dmat4>>& poses, TwoLevelTiming* timing,
                                  const FrameGeometry& geometry) {
    require(!poses.empty(), scene.source + ": no frame to build");
    const MeshAnimation* animation = geometry.animation;
    std::vector<bool> deforming(scene.meshes.size(), false);
    for (uint32_t m = 0; animation && m < scene.meshes.size(); ++m)
        deforming[m] = scene.meshes[m].triangle_count() > 0 && animation->deforms(m);
    const std::vector<uint32_t> cls = blas_classes(scene, deforming);
    // A deforming mesh's BLAS per frame, followed by the frame policy (frame_policy.h).
    std::vector<std::unique_ptr<FrameTree>> blas_tree(scene.meshes.size());
    for (uint32_t m = 0; m < scene.meshes.size(); ++m)
        if (deforming[m]) blas_tree[m] = std::make_unique<FrameTree>(geometry.policy);
    FrameTree tlas_tree(geometry.policy);
    std::vector<json> frame_build(poses.size(), json::object());
    for (json& b : frame_build) b["blas"] = json::array();

    // The mesh's positions in frame f (deforming meshes only): the scene posed.
    auto posed = [&](uint32_t f) {
        Scene s = scene;
        for (uint32_t m = 0; m < s.meshes.size(); ++m)
            if (deforming[m]) animation->pose(m, f, &s.meshes[m].positions);
        return s;
    };
    // What a deforming BLAS's frame did: its action, tree, SAH cost and the bytes it wrote.
    auto record_blas = [&](uint32_t f, uint32_t mesh, uint32_t blas, const AccelImage& img) {
        json r = blas_tree[mesh]->done(options.build);
        r["mesh"] = mesh;
        r["blas"] = blas;
        r["triangles"] = scene.meshes[mesh].triangle_count();
        r["bytes"] = img.footprint_bytes();
        frame_build[f]["blas"].push_back(r);
    };

    auto t0 = std::chrono::steady_clock::now();
    const bool any_deforming = std::find(deforming.begin(), deforming.end(), true) != deforming.end();
    // Frame 0 of a deforming scene is its first pose (a copy); a still scene is used as it is.
    std::optional<Scene> first_pose;
    if (any_deforming) first_pose = posed(0);
    BlasSet blases = build_blases(first_pose ? *first_pose : scene, options, cls, [&](uint32_t m) {
        return deforming[m] ? blas_tree[m]->reuse_for(0) : nullptr;
    });
    if (timing) timing->blas_ms = ms_since(t0);
    std::vector<std::vector<uint32_t>> blas_of_mesh(poses.size(), blases.blas_of_mesh);
    for (uint32_t m = 0; m < scene.meshes.size(); ++m)
        if (deforming[m]) record_blas(0, m, blases.blas_of_mesh[m], blases.images[blases.blas_of_mesh[m]]);

    // Later frames: each deforming mesh's BLAS built or refitted from its frame's positions,
    // at its own addresses (appended), like a driver writing the frame's acceleration structure.
    AccelOptions blas_options = options;
    blas_options.two_level = false;
    for (uint32_t f = 1; f < poses.size() && any_deforming; ++f) {
        t0 = std::chrono::steady_clock::now();
        const Scene frame_scene = posed(f);
        for (uint32_t m = 0; m < scene.meshes.size(); ++m) {
            if (!deforming[m]) continue;
            blas_options.tree_reuse = blas_tree[m]->reuse_for(f);
            blases.images.push_back(build_accel(mesh_scene(frame_scene, m), blas_options));
            blas_of_mesh[f][m] = uint32_t(blases.images.size() - 1);
            record_blas(f, m, blas_of_mesh[f][m], blases.images.back());
        }
        if (timing) timing->blas_frame_ms.push_back(ms_since(t0));
    }

    // Every frame's TLAS over its BLASes (a driver rebuilding, or refitting, the top level).
    std::vector<TlasFrame> frames;
    for (uint32_t f = 0; f < poses.size(); ++f) {
        const std::vector<glm::dmat4>& pose = poses[f];
        require(pose.size() == scene.instances.size(), scene.source + ": a frame poses " +
                                                           std::to_string(pose.size()) + " of " +
                                                           std::to_string(scene.instances.size()) + " instances");
        // Spheres stay spheres only under similarities (check_instance_transforms, per frame).
        for (size_t i = 0; i < pose.size(); ++i) check_curved_similarity(scene, i, pose[i], " in frame " + std::to_string(f));
        t0 = std::chrono::steady_clock::now();
        frames.push_back(build_tlas(scene, blases, blas_of_mesh[f], pose, options, tlas_tree.reuse_for(f)));
        frame_build[f]["tlas"] = tlas_tree.done(options.build);
        frame_build[f]["tlas"]["instances"] = frames.back().records.size();
        frame_build[f]["tlas"]["bytes"] =
            frames.back().tlas.nodes.size() * sizeof(HwNode) + frames.back().records.size() * sizeof(InstanceRecord);
        if (timing) timing->tlas_ms.push_back(ms_since(t0));
    }

    // Frames' TLASes back to back in "tlas_nodes", their records back to back in "instances".
    AccelImage image;
    image.kind = "two_level";
    image.bounds = frames[0].bounds;
    uint64_t node_total = 0, record_total = 0;
    json frame_list = json::array();
    for (size_t k = 0; k < frames.size(); ++k) {
        const TlasFrame& f = frames[k];
        frame_list.push_back({{"tlas_first", node_total}, {"tlas_count", f.tlas.nodes.size()},
                              {"instances_first", record_total}, {"instances_count", f.records.size()},
                              {"build", frame_build[k]}});
        node_total += f.tlas.nodes.size();
        record_total += f.records.size();
    }
    // (References taken after both regions exist: adding a region may move the others.)
    image.add_region<HwNode>("tlas_nodes", DataKind::node, node_total);
    image.add_region<InstanceRecord>("instances", DataKind::instance, record_total);
    Region& nodes = image.regions[image.regions.size() - 2];
    Region& records = image.regions.back();
    for (size_t f = 0; f < frames.size(); ++f) {
        std::memcpy(nodes.records<HwNode>() + frame_list[f]["tlas_first"].get<uint64_t>(), frames[f].tlas.nodes.data(),
                    frames[f].tlas.nodes.size() * sizeof(HwNode));
        std::memcpy(records.records<InstanceRecord>() + frame_list[f]["instances_first"].get<uint64_t>(),
                    frames[f].records.data(), frames[f].records.size() * sizeof(InstanceRecord));
    }
    const uint64_t tlas_bytes = nodes.size_bytes() + records.size_bytes();
    uint64_t blas_bytes = 0;
    json blas_list = add_blas_regions(image, blases.images, &blas_bytes);
    image.params = {{"blas_kind", options.kind}, {"blas", blas_list}};
    if (frames.size() > 1) image.params["frames"] = frame_list;  // one frame: the whole regions
    image.place_regions();

    json blas_stats = json::array();
    for (const AccelImage& b : blases.images) blas_stats.push_back(b.stats);
    image.stats = {{"blas_kind", options.kind},
                   {"blases", blases.images.size()},
                   {"instances", blases.placed.size()},
                   {"tlas_nodes", frames[0].tlas.nodes.size()},
                   {"tlas_bytes", tlas_bytes},
                   {"blas_bytes", blas_bytes},
                   {"blas", blas_stats}};
    if (frames.size() > 1) image.stats["frames"] = frames.size();
    return image;
}

}  // namespace rtsim
