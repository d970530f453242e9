// Building a two-level image (two_level.h): one BLAS per used mesh in object space, the TLAS a
// binned-SAH binary BVH over the instances' world boxes with one instance per leaf.
#include <cmath>
#include <cstring>
#include <algorithm>
#include <limits>
#include <numeric>
#include <unordered_map>

#include "traces/accel/two_level/two_level.h"
#include "traces/bvh/build_tree.h"
#include "traces/common/error.h"
#include "traces/scene/scene.h"

namespace rtsim {

using nlohmann::json;

namespace {

/// What a triangle's BLAS record depends on besides its vertices: its alpha test.
int64_t alpha_key(const Scene& scene, uint32_t material) {
    const Material& m = scene.materials[material];
    return m.alpha_mode == AlphaMode::mask ? int64_t(std::lround(m.alpha_coverage * 255.0f)) : -1;
}

bool same_geometry(const Scene& scene, const Mesh& a, const Mesh& b) {
    if (a.positions.size() != b.positions.size() ||
        std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(Vec3)) != 0)
        return false;
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

AccelImage build_two_level(const Scene& scene, const AccelOptions& options) {
    // One BLAS per geometry some instance places (meshes without triangles are skipped; meshes
    // of equal vertices and alpha tests share one, whatever their materials).
    const std::vector<uint32_t> cls = geometry_classes(scene);
    std::vector<int32_t> blas_of_class(scene.meshes.size(), -1);
    std::vector<AccelImage> blases;
    AccelOptions blas_options = options;
    blas_options.two_level = false;
    std::vector<uint32_t> placed;  // instances with geometry, scene order
    for (uint32_t i = 0; i < scene.instances.size(); ++i) {
        const uint32_t mesh = scene.instances[i].mesh;
        require(mesh < scene.meshes.size(), scene.source + ": instance " + std::to_string(i) + " has no mesh");
        if (scene.meshes[mesh].triangle_count() == 0) continue;
        if (blas_of_class[cls[mesh]] < 0) {
            blas_of_class[cls[mesh]] = int32_t(blases.size());
            blases.push_back(build_accel(mesh_scene(scene, cls[mesh]), blas_options));
        }
        placed.push_back(i);
    }
    auto blas_of_mesh = [&](uint32_t mesh) { return uint32_t(blas_of_class[cls[mesh]]); };
    require(!placed.empty(), scene.source + ": the scene has no triangles");

    std::vector<Aabb> boxes(placed.size());
    Aabb bounds;
    for (size_t k = 0; k < placed.size(); ++k) {
        const Instance& inst = scene.instances[placed[k]];
        boxes[k] = world_box(blases[blas_of_mesh(inst.mesh)].bounds, inst.object_to_world);
        bounds.grow(boxes[k]);
    }
    BuildConfig tlas_config = options.build;
    tlas_config.max_leaf_size = 1;
    const Scene tlas_input = box_scene(boxes);
    const HwBvh tlas = flatten_bvh(build_binned_sah(tlas_input.triangles, tlas_config), tlas_input, tlas_config);

    AccelImage image;
    image.kind = "two_level";
    image.bounds = bounds;
    Region& nodes = image.add_region("tlas_nodes", DataKind::node, sizeof(HwNode), tlas.nodes.size());
    std::memcpy(nodes.bytes.data(), tlas.nodes.data(), nodes.size_bytes());
    Region& records = image.add_region("instances", DataKind::instance, sizeof(InstanceRecord), placed.size());
    InstanceRecord* rec = records.records<InstanceRecord>();
    for (size_t k = 0; k < placed.size(); ++k) {  // in TLAS leaf order
        const uint32_t id = placed[tlas.triangles[k].prim];
        const Instance& inst = scene.instances[id];
        rec[k] = InstanceRecord{};
        store_affine_rows(glm::inverse(inst.object_to_world), rec[k].world_to_object);
        store_affine_rows(inst.object_to_world, rec[k].object_to_world);
        rec[k].blas = blas_of_mesh(inst.mesh);
        rec[k].prim_base = inst.prim_base;
        rec[k].instance = id;
    }

    // The BLASes' regions, concatenated per name; each BLAS starts on a 64-byte boundary.
    json blas_list = json::array();
    for (const AccelImage& b : blases) blas_list.push_back({{"params", b.params}, {"bounds", bounds_json(b.bounds)},
                                                            {"first", json::object()}, {"count", json::object()}});
    uint64_t blas_bytes = 0;
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
        Region& out = image.add_region("blas_" + proto.name, proto.kind, uint32_t(rb), total);
        for (size_t b = 0; b < blases.size(); ++b) {
            const Region& r = blases[b].region(proto.name);
            std::memcpy(out.bytes.data() + first[b] * rb, r.bytes.data(), r.size_bytes());
        }
        blas_bytes += out.size_bytes();
    }
    image.params = {{"blas_kind", options.kind}, {"blas", blas_list}};
    image.place_regions();

    json blas_stats = json::array();
    for (const AccelImage& b : blases) blas_stats.push_back(b.stats);
    image.stats = {{"blas_kind", options.kind},
                   {"blases", blases.size()},
                   {"instances", placed.size()},
                   {"tlas_nodes", tlas.nodes.size()},
                   {"tlas_bytes", image.region("tlas_nodes").size_bytes() + image.region("instances").size_bytes()},
                   {"blas_bytes", blas_bytes},
                   {"blas", blas_stats}};
    return image;
}

}  // namespace rtsim
