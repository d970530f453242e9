// The oriented BVH's build: the binary tree flattened as a bvh2, then each node's rotation fitted
// (obvh.h).
#include <algorithm>
#include <cmath>
#include <thread>

#include "traces/accel/bvh2/bvh2.h"
#include "traces/accel/obvh/obvh.h"
#include "traces/accel/obvh/obvh_rotate.h"
#include "traces/common/error.h"
#include "traces/scene/scene.h"

namespace rtsim {

namespace {

/// Row-major rotation by `angle` about coordinate axis `axis`: the other two axes (u, v) turn.
Rotation axis_rotation(int axis, double angle) {
    const double c = std::cos(angle), s = std::sin(angle);
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    Rotation m{};
    m[3 * axis + axis] = 1.0f;
    m[3 * u + u] = float(c), m[3 * u + v] = float(-s);
    m[3 * v + u] = float(s), m[3 * v + v] = float(c);
    return m;
}

/// Tilt about x after a turn about z, in double then rounded once: Rx(tilt) Rz(turn).
Rotation turn_then_tilt(double turn, double tilt) {
    const double cz = std::cos(turn), sz = std::sin(turn), cx = std::cos(tilt), sx = std::sin(tilt);
    return {float(cz), float(-sz), 0.0f, float(cx * sz), float(cx * cz), float(-sx),
            float(sx * sz), float(sx * cz), float(cx)};
}

}  // namespace

std::vector<Rotation> obb_rotation_table(const ObbConfig& obb) {
    const uint32_t tilts = std::max(obb.tilt_steps, 1u) - 1 - (obb.tilt_steps % 2 == 0 && obb.tilt_steps >= 2);
    const uint64_t single = 3 * uint64_t(std::max(obb.angle_steps, 1u) - 1), tilted = uint64_t(obb.turn_steps) * tilts;
    require(single + tilted >= 1 && single + tilted < kNoRotation,
            "obvh2: obb_angle_steps, obb_turn_steps and obb_tilt_steps give " + std::to_string(single) + " + " +
                std::to_string(tilted) + " rotations: the table needs 1 to 126 (the node's 7-bit index less 'none')");
    std::vector<Rotation> table;
    for (int axis = 0; axis < 3; ++axis)
        for (uint32_t k = 1; k < obb.angle_steps; ++k) table.push_back(axis_rotation(axis, k * (M_PI / 2) / obb.angle_steps));
    // Quarter turns map a box to a box, but a turn and a tilt each need a half turn here: over
    // a quarter the tilted frames would miss half the directions' azimuths.
    // A quarter tilt about x maps the turned box to itself turned about z (no new frame): skipped.
    for (uint32_t i = 0; i < obb.turn_steps; ++i)
        for (uint32_t j = 1; j < obb.tilt_steps; ++j)
            if (2 * j != obb.tilt_steps) table.push_back(turn_then_tilt(i * M_PI / obb.turn_steps, j * M_PI / obb.tilt_steps));
    return table;
}

namespace {

double obb_half_area(const Aabb& b) {
    if (b.empty()) return 0.0;
    const glm::dvec3 e = glm::dvec3(b.hi) - glm::dvec3(b.lo);
    return e.x * e.y + e.y * e.z + e.z * e.x;
}

Aabb obb_slot_aabb(const HwNode& n, int c) {
    Aabb b;
    if (n.child_count[c] == kEmptyChild) return b;
    for (int a = 0; a < 3; ++a) b.lo[a] = n.lo(c, a), b.hi[a] = n.hi(c, a);
    return b;
}

/// The best frame found for one node: its rotation, the summed child area there, both boxes.
struct ObbNodeFit {
    double cost = 0.0;
    uint8_t rotation = kNoRotation;
    Aabb box[2];
};

/// Grows `box` by record `rec` in the frame of rotation `m`: a triangle's rotated vertices; a
/// sphere's rotated centre, or a capsule's rotated ends, widened by their radii (a sphere is the
/// same in every frame).
void grow_rotated(Aabb& box, const float* m, const HwTriangle& rec) {
    auto point = [&](const float* p) { return obb_rotate(m, Vec3(p[0], p[1], p[2])); };
    if (!is_curved(rec)) {
        box.grow(point(rec.v0)), box.grow(point(rec.v1)), box.grow(point(rec.v2));
        return;
    }
    // A capsule's ends each by their own radius: the swept sphere's box is its end spheres'.
    const float r0 = is_sphere(rec) ? rec.v1[0] : rec.v2[0], r1 = is_sphere(rec) ? rec.v1[0] : rec.v2[1];
    const Vec3 c0 = point(rec.v0), c1 = is_sphere(rec) ? c0 : point(rec.v1);
    box.grow(c0 - Vec3(r0)), box.grow(c0 + Vec3(r0));
    box.grow(c1 - Vec3(r1)), box.grow(c1 + Vec3(r1));
}

/// Tries rotations [first, last) on every node, keeping in `fits` each node's best below its
/// current cost (a lower index wins ties: the result does not depend on how rotations are split
/// among threads).
void fit_rotations(const HwNode* nodes, uint64_t count, const HwTriangle* tris, const std::vector<Rotation>& table,
                   size_t first, size_t last, std::vector<ObbNodeFit>& fits) {
    std::vector<Aabb> subtree(count);
    for (size_t r = first; r < last; ++r) {
        const float* m = table[r].data();
        // Children come after their parents (depth-first layout): one backward pass is bottom-up.
        for (uint64_t i = count; i-- > 0;) {
            const HwNode& n = nodes[i];
            Aabb box[2];
            for (int c = 0; c < 2; ++c) {
                const uint32_t k = n.child_count[c];
                if (k == kEmptyChild) continue;
                if (k == 0) {
                    box[c] = subtree[n.child_ref[c]];
                    continue;
                }
                for (uint32_t t = n.child_ref[c]; t < n.child_ref[c] + k; ++t) grow_rotated(box[c], m, tris[t]);
            }
            subtree[i] = box[0];
            subtree[i].grow(box[1]);
            const double cost = obb_half_area(box[0]) + obb_half_area(box[1]);
            ObbNodeFit& f = fits[i];
            if (cost < f.cost) f = ObbNodeFit{cost, uint8_t(r), {box[0], box[1]}};
        }
    }
}

/// Each node's fit with its kept rotation `kept[i]`, counting the node boxes computed in
/// *node_frames. A node's children must be boxed in its frame, so every subtree is boxed in the
/// frame of each oriented ancestor, bottom-up (exact: a box of a union is the union of the
/// boxes): a node's frames are the distinct rotations above it, its children's those and its
/// own. A node whose kept frame no longer beats its axis-aligned children's area (the refit's,
/// in `aabb_cost`; without the build's `min_gain`, which decided whether to orient it) drops
/// the rotation, and a later refit keeps it dropped: only a rebuild orients a node again.
std::vector<ObbNodeFit> kept_rotation_fits(const HwNode* nodes, uint64_t count, const HwTriangle* tris,
                                           const std::vector<Rotation>& table, const std::vector<uint8_t>& kept,
                                           const std::vector<double>& aabb_cost, uint64_t* node_frames) {
    require(kept.size() == count, "obvh2: the kept rotations are for " + std::to_string(kept.size()) +
                                      " nodes, the refitted tree has " + std::to_string(count));
    // Top-down: each node's frames (`frames`, its ancestors') and its children's (`below`).
    std::vector<std::vector<uint8_t>> frames(count), below(count);
    for (uint64_t i = 0; i < count; ++i) {
        require(kept[i] == kNoRotation || kept[i] < table.size(), "obvh2: a kept rotation outside the table");
        below[i] = frames[i];
        if (kept[i] != kNoRotation && std::find(below[i].begin(), below[i].end(), kept[i]) == below[i].end())
            below[i].push_back(kept[i]);
        for (int c = 0; c < 2; ++c)
            if (nodes[i].child_count[c] == 0) {
                // The depth-first layout puts children after their parents: one pass each way.
                require(nodes[i].child_ref[c] > i, "obvh2: node " + std::to_string(i) + " has a child before it");
                frames[nodes[i].child_ref[c]] = below[i];
            }
    }
    // Bottom-up: each node's subtree boxed in each of its frames (children's freed once used).
    std::vector<std::vector<Aabb>> subtree(count);
    std::vector<ObbNodeFit> fits(count);
    auto child_box = [&](const HwNode& n, int c, uint8_t r, size_t slot) {
        Aabb box;
        if (n.child_count[c] == kEmptyChild) return box;
        if (n.child_count[c] == 0) return subtree[n.child_ref[c]][slot];
        for (uint32_t t = n.child_ref[c]; t < n.child_ref[c] + n.child_count[c]; ++t) grow_rotated(box, table[r].data(), tris[t]);
        return box;
    };
    for (uint64_t i = count; i-- > 0;) {
        const HwNode& n = nodes[i];
        const std::vector<uint8_t>& own = frames[i];
        auto slot_of = [&](uint8_t r) { return size_t(std::find(below[i].begin(), below[i].end(), r) - below[i].begin()); };
        subtree[i].resize(own.size());
        for (size_t f = 0; f < own.size(); ++f) {
            const Aabb a = child_box(n, 0, own[f], slot_of(own[f])), b = child_box(n, 1, own[f], slot_of(own[f]));
            subtree[i][f] = a;
            subtree[i][f].grow(b);
        }
        *node_frames += own.size();
        fits[i].cost = aabb_cost[i];
        if (kept[i] != kNoRotation) {
            const size_t slot = slot_of(kept[i]);
            const Aabb a = child_box(n, 0, kept[i], slot), b = child_box(n, 1, kept[i], slot);
            const double cost = obb_half_area(a) + obb_half_area(b);
            *node_frames += std::find(own.begin(), own.end(), kept[i]) == own.end();  // else boxed above
            if (cost < aabb_cost[i]) fits[i] = ObbNodeFit{cost, kept[i], {a, b}};
        }
        for (int c = 0; c < 2; ++c)
            if (n.child_count[c] == 0) std::vector<Aabb>().swap(subtree[n.child_ref[c]]);
    }
    return fits;
}

}  // namespace

AccelImage obvh2_image(const BuildTree& tree, const Scene& scene, const BuildConfig& config, const ObbConfig& obb,
                       const std::string& builder, unsigned threads, const std::vector<uint8_t>* kept) {
    const std::vector<Rotation> table = obb_rotation_table(obb);
    AccelImage flat = bvh2_image(tree, scene, config, builder);
    const Region& flat_nodes = flat.region("nodes");
    const Region& flat_tris = flat.region("triangles");
    const HwNode* nodes = flat_nodes.records<HwNode>();
    const HwTriangle* tris = flat_tris.records<HwTriangle>();
    const uint64_t count = flat_nodes.count;

    // Each node starts at its axis-aligned children's area, lowered by the gain it must beat.
    std::vector<ObbNodeFit> start(count);
    std::vector<double> aabb_cost(count);
    for (uint64_t i = 0; i < count; ++i) {
        aabb_cost[i] = obb_half_area(obb_slot_aabb(nodes[i], 0)) + obb_half_area(obb_slot_aabb(nodes[i], 1));
        start[i].cost = aabb_cost[i] * (1.0 - double(obb.min_gain));
    }
    // Each node's chosen frame: its kept rotation, or the best of the table.
    std::vector<ObbNodeFit> chosen;
    uint64_t node_frames = 0;
    if (kept) {
        chosen = kept_rotation_fits(nodes, count, tris, table, *kept, aabb_cost, &node_frames);
    } else {
        // Rotations split among threads, each with its own fits, merged in rotation order.
        const size_t workers = std::max<size_t>(1, std::min<size_t>(threads ? threads : 1, table.size()));
        std::vector<std::vector<ObbNodeFit>> fits(workers, start);
        std::vector<std::thread> pool;
        for (size_t w = 0; w < workers; ++w) {
            const size_t first = table.size() * w / workers, last = table.size() * (w + 1) / workers;
            auto job = [&, w, first, last] { fit_rotations(nodes, count, tris, table, first, last, fits[w]); };
            if (w + 1 == workers) job();
            else pool.emplace_back(job);
        }
        for (std::thread& t : pool) t.join();
        chosen = start;
        for (uint64_t i = 0; i < count; ++i)
            for (const std::vector<ObbNodeFit>& f : fits)
                if (f[i].cost < chosen[i].cost) chosen[i] = f[i];  // workers in rotation order: ties keep the lower
        node_frames = count * table.size();
    }

    AccelImage image;
    image.kind = "obvh2";
    image.bounds = flat.bounds;
    Region& out = image.add_region<HwObbNode>("nodes", DataKind::node, count);
    Region& out_tris = image.add_region<HwTriangle>("triangles", DataKind::triangle, flat_tris.count, false);
    std::copy(tris, tris + flat_tris.count, out_tris.records<HwTriangle>());
    HwObbNode* o = out.records<HwObbNode>();
    uint64_t oriented = 0;
    double area_before = 0, area_after = 0;
    std::vector<double> slot_area(2 * count, 0.0);  // each child slot's area in its node's frame
    for (uint64_t i = 0; i < count; ++i) {
        const HwNode& n = nodes[i];
        const ObbNodeFit* best = &chosen[i];
        const bool rotate = best->rotation != kNoRotation;
        o[i].rotation = best->rotation;
        for (int c = 0; c < 2; ++c) {
            require(n.child_count[c] == kEmptyChild || n.child_count[c] < kObbEmptyChild,
                    "obvh2: a leaf of " + std::to_string(n.child_count[c]) + " triangles (at most 65534)");
            o[i].child_ref[c] = n.child_ref[c];
            o[i].child_count[c] = n.child_count[c] == kEmptyChild ? kObbEmptyChild : uint16_t(n.child_count[c]);
            const Aabb box = rotate ? best->box[c] : obb_slot_aabb(n, c);
            for (int a = 0; a < 3; ++a) {
                o[i].bounds[a][0][c] = n.child_count[c] == kEmptyChild ? n.lo(c, a) : box.lo[a];
                o[i].bounds[a][1][c] = n.child_count[c] == kEmptyChild ? n.hi(c, a) : box.hi[a];
            }
            slot_area[2 * i + c] = obb_half_area(box);
        }
        oriented += rotate;
        area_before += aabb_cost[i];
        area_after += rotate ? best->cost : aabb_cost[i];
    }
    image.leaf_starts = flat.leaf_starts;
    nlohmann::json rotations = nlohmann::json::array();
    for (const Rotation& m : table) rotations.push_back(m);
    image.params["rotations"] = rotations;
    image.place_regions();

    // SAH cost with each node's box as its parent holds it (in the parent's frame).
    const double root = obb_half_area(flat.bounds);
    auto weight = [root](double a) { return root > 0 ? a / root : 1.0; };
    double sah = count ? config.traversal_cost : 0.0;
    for (uint64_t i = 0; i < count; ++i)
        for (int c = 0; c < 2; ++c) {
            const uint32_t k = nodes[i].child_count[c];
            if (k == kEmptyChild) continue;
            sah += (k == 0 ? double(config.traversal_cost) : double(config.intersection_cost) * k) *
                   weight(slot_area[2 * i + c]);
        }
    image.stats = flat.stats;
    image.stats["sah_cost_aabb"] = flat.stats["sah_cost"];
    image.stats["sah_cost"] = sah;
    // The fit's wall time is in the build's (build_ms): a trace holds no wall times.
    image.stats["obvh2"] = {{"rotations", table.size()},
                            {"angle_steps", obb.angle_steps},
                            {"turn_steps", obb.turn_steps},
                            {"tilt_steps", obb.tilt_steps},
                            {"rotations_kept", kept != nullptr},
                            {"fit_node_frames", node_frames},
                            {"min_gain", obb.min_gain},
                            {"oriented_nodes", oriented},
                            {"oriented_fraction", count ? double(oriented) / double(count) : 0.0},
                            {"child_area_ratio", area_before > 0 ? area_after / area_before : 1.0}};
    return image;
}

std::vector<uint8_t> obvh2_rotations(const AccelImage& image) {
    const Region& nodes = image.region("nodes");
    const HwObbNode* n = nodes.records<HwObbNode>();
    std::vector<uint8_t> out(nodes.count);
    for (uint64_t i = 0; i < nodes.count; ++i) out[i] = n[i].rotation;
    return out;
}

}  // namespace rtsim
