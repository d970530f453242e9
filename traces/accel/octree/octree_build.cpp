// The adaptive octree's builder (octree.h): top down, a cell listing more than max_leaf_size
// references is cut at its centre and each reference (the part of a triangle inside the cell) is
// clipped into the children it reaches (conservatively, in double: traces/bvh/sbvh_clip.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "traces/accel/octree/octree.h"
#include "traces/accel/ref_list.h"
#include "traces/accel/spatial_params.h"
#include "traces/bvh/build_tree.h"
#include "traces/bvh/sbvh_clip.h"
#include "traces/common/build_budget.h"
#include "traces/common/error.h"
#include "traces/scene/scene.h"

namespace rtsim {
namespace {

struct Ref {
    Aabb box;  ///< the triangle's part in the cell (conservative)
    uint32_t prim;
};

double half_area(const Aabb& b) {
    const double x = double(b.hi.x) - b.lo.x, y = double(b.hi.y) - b.lo.y, z = double(b.hi.z) - b.lo.z;
    return x * y + y * z + z * x;
}

/// References a build may clip and list in all, per triangle and at least. Ordinary scenes take
/// 13-50 per triangle with the default max_leaf_size of 8; a leaf size below the number of
/// triangles meeting at a mesh vertex cuts cells down to max_depth around every vertex (the 1,034
/// triangles of rotated_walls with max_leaf_size=2: 19 M references, 9.5 M nodes, 15 s), and
/// overlapping coplanar triangles never thin out, so each level quadruples their references down
/// to max_depth (4^16 cells of a plane) (docs/validation.md, "third round").
constexpr double kOctWorkPerTriangle = 256.0;
constexpr double kOctMinWork = double(1u << 25);

class OctreeBuilder {
public:
    OctreeBuilder(const Scene& scene, const OctreeConfig& c)
        : m_scene(scene),
          m_c(c),
          m_work_limit(std::max(kOctMinWork, kOctWorkPerTriangle * double(scene.triangles.size()))),
          m_live(scene.triangles.size()) {}

    /// Builds node `index` over `cell`; `weight`: its share of the root's references (the
    /// leaves' shares add up to 1, so the work done over the share finished extrapolates the
    /// whole build).
    void build(uint32_t index, const Aabb& cell, std::vector<Ref>& refs, uint32_t depth, double weight);
    std::vector<OctNode> nodes;
    std::vector<uint32_t> list;
    double root_area = 1.0, sah = 0.0;
    uint64_t leaves = 0, max_leaf = 0, deepest = 0;
    double work() const { return m_work; }
    double work_limit() const { return m_work_limit; }

private:
    void leaf(uint32_t index, const Aabb& cell, const std::vector<Ref>& refs, double weight);
    /// Before `more` references are clipped: refuses a build whose work (so far, or extrapolated
    /// from the share finished) passes its limit.
    void check_work(uint64_t more);
    /// Before `more` clipped references are kept for `new_nodes` children: refuses more nodes
    /// than the layout indexes or more memory than a build may take.
    void check_room(uint64_t more, uint32_t new_nodes);
    [[noreturn]] void refuse(const std::string& why) const;
    /// The parts of `r` on either side of `plane` of `axis` (empty boxes where it does not reach).
    void split(const Ref& r, int axis, float plane, Aabb* lower, Aabb* upper) const;

    const Scene& m_scene;
    OctreeConfig m_c;
    double m_work_limit;
    double m_work = 0.0;       ///< references clipped or listed so far
    double m_done = 0.0;       ///< the share of the root's references in finished leaves
    uint64_t m_live = 0;       ///< references held in the lists of cells not yet finished
};

void OctreeBuilder::refuse(const std::string& why) const {
    char settings[160];
    std::snprintf(settings, sizeof settings, "octree (max_depth=%u, max_leaf_size=%u, clip=%s)", m_c.max_depth,
                  m_c.max_leaf_size, m_c.clip ? "true" : "false");
    throw Error(std::string(settings) + ": " + why +
                "; many triangles overlapping in one plane (or one point) never thin out to max_leaf_size, so "
                "their cells are cut down to max_depth: lower max_depth (--build-set max_depth=8) or raise "
                "max_leaf_size, or use another structure");
}

void OctreeBuilder::check_work(uint64_t more) {
    m_work += double(more);
    const double share = std::max(m_done, 1e-12);
    // Past a quarter of the budget the share finished extrapolates the whole, within a factor of
    // about 3 (depth first, the first subtrees are the deepest): one estimated at 8 times the
    // budget is refused early.
    if (m_work <= m_work_limit && !(m_work > m_work_limit / 4 && m_work / share > 8 * m_work_limit)) return;
    const double n = double(m_scene.triangles.size());
    char text[400];
    std::snprintf(text, sizeof text,
                  "the build would clip about %.3g references (%.3g per triangle; %.3g so far for %.2g%% of the "
                  "scene) into about %.3g nodes, more than the %.3g references of work a build of %.0f triangles "
                  "may do",
                  m_work / share, m_work / share / n, m_work, 100.0 * m_done, double(nodes.size()) / share,
                  m_work_limit, n);
    refuse(text);
}

void OctreeBuilder::check_room(uint64_t more, uint32_t new_nodes) {
    char text[300];
    if (double(nodes.size()) + new_nodes > double(OctNode::kMaxIndex)) {
        std::snprintf(text, sizeof text, "more than 2^24 nodes (the layout's child index), about %.3g estimated",
                      double(nodes.size()) / std::max(m_done, 1e-12));
        refuse(text);
    }
    const double bytes = double(nodes.size() + new_nodes) * sizeof(OctNode) + double(list.size()) * 4.0 +
                         double(m_live + more) * sizeof(Ref);
    std::snprintf(text, sizeof text, "%zu nodes, %zu references listed, %llu being clipped", nodes.size(),
                  list.size(), static_cast<unsigned long long>(m_live + more));
    try {
        check_build_memory(bytes, "the tree", text, "lower max_depth or raise max_leaf_size");
    } catch (const Error& e) {
        refuse(e.what());
    }
}

void OctreeBuilder::split(const Ref& r, int axis, float plane, Aabb* lower, Aabb* upper) const {
    if (r.box.hi[axis] <= plane && !(r.box.lo[axis] == plane)) {  // wholly below (touching allowed)
        *lower = r.box, *upper = Aabb{};
        return;
    }
    if (r.box.lo[axis] >= plane && !(r.box.hi[axis] == plane)) {
        *lower = Aabb{}, *upper = r.box;
        return;
    }
    if (r.box.lo[axis] == plane && r.box.hi[axis] == plane) {  // flat in the plane: the lower side
        *lower = r.box, *upper = Aabb{};
        return;
    }
    if (m_c.clip) {
        ClippedTriangle(m_scene.triangles[r.prim], r.box).split(axis, plane, lower, upper);
    } else {
        *lower = *upper = r.box;
        lower->hi[axis] = upper->lo[axis] = plane;
    }
}

void OctreeBuilder::leaf(uint32_t index, const Aabb& cell, const std::vector<Ref>& refs, double weight) {
    m_done += weight;
    m_work += double(refs.size());
    std::vector<uint32_t> prims;
    for (const Ref& r : refs) prims.push_back(r.prim);
    std::sort(prims.begin(), prims.end());
    require(list.size() + prims.size() < (1ull << 32), "octree: more than 2^32 references");
    nodes[index] = OctNode::make_leaf(uint32_t(list.size()), uint32_t(prims.size()));
    list.insert(list.end(), prims.begin(), prims.end());
    sah += half_area(cell) / root_area * double(prims.size());
    leaves += 1;
    max_leaf = std::max<uint64_t>(max_leaf, prims.size());
}

void OctreeBuilder::build(uint32_t index, const Aabb& cell, std::vector<Ref>& refs, uint32_t depth, double weight) {
    deepest = std::max<uint64_t>(deepest, depth);
    // The centre: each axis with extent is halved; one without keeps its upper bound (not cut).
    float centre[3];
    bool cut_any = false;
    for (int a = 0; a < 3; ++a) {
        const float lo = cell.lo[a], hi = cell.hi[a], mid = lo + (hi - lo) * 0.5f;
        const bool cut = mid > lo && mid < hi;
        centre[a] = cut ? mid : hi;
        cut_any = cut_any || cut;
    }
    if (refs.size() <= m_c.max_leaf_size || depth >= m_c.max_depth || !cut_any) return leaf(index, cell, refs, weight);
    // Each reference clipped into the children it reaches: one axis at a time.
    check_work(refs.size());
    std::vector<Ref> child[8];
    for (const Ref& r : refs) {
        Aabb part[8];
        part[0] = r.box;
        for (int a = 0; a < 3; ++a) {
            if (!(centre[a] < cell.hi[a])) continue;  // axis not cut: everything on the lower side
            for (uint32_t c = 0; c < 8; ++c) {
                if ((c >> a & 1u) || part[c].empty()) continue;
                Ref piece{part[c], r.prim};
                split(piece, a, centre[a], &part[c], &part[c | 1u << a]);
            }
        }
        for (uint32_t c = 0; c < 8; ++c)
            if (!part[c].empty()) child[c].push_back(Ref{part[c], r.prim});
    }
    // A cut that lists every reference in every child it stores, with more than one stored,
    // only multiplies references (large triangles covering the cell): it stays a leaf. A cut
    // that leaves every reference in one child still shrinks the cell (empty space cut off).
    bool separates = false;
    uint32_t mask = 0, stored = 0;
    for (uint32_t c = 0; c < 8; ++c) {
        separates = separates || (!child[c].empty() && child[c].size() < refs.size());
        if (!child[c].empty()) mask |= 1u << c, ++stored;
    }
    if (!separates && stored > 1) return leaf(index, cell, refs, weight);
    uint64_t total = 0;
    for (uint32_t c = 0; c < 8; ++c) total += child[c].size();
    check_room(total, stored);
    m_live += total;
    m_live -= refs.size();  // a cell's list is freed once its children hold the parts
    std::vector<Ref>().swap(refs);
    const uint32_t first = uint32_t(nodes.size());
    nodes[index] = OctNode::interior(mask, first, centre);
    nodes.resize(nodes.size() + stored);
    sah += half_area(cell) / root_area;
    uint32_t k = first;
    for (uint32_t c = 0; c < 8; ++c) {
        if (child[c].empty()) continue;
        const double share = weight * double(child[c].size()) / double(total);
        build(k++, octree_child_cell(cell, centre, c), child[c], depth + 1, share);
        m_live -= child[c].size();  // a leaf's list (an interior child freed its own)
        std::vector<Ref>().swap(child[c]);
    }
}

}  // namespace

AccelImage octree_image(const Scene& scene, const OctreeConfig& config) {
    const size_t n = scene.triangles.size();
    require(n > 0, "octree: the scene has no triangles");
    require(n < (size_t(1) << 31), "octree: too many triangles (>= 2^31)");
    require(config.max_depth >= 1 && config.max_depth <= kOctMaxDepth && config.max_leaf_size >= 1,
            "OctreeConfig: max_depth must be in 1.." + std::to_string(kOctMaxDepth) + " and max_leaf_size >= 1");
    std::vector<Ref> refs(n);
    Aabb bounds;
    for (size_t i = 0; i < n; ++i) {
        for (const Vec3& v : {scene.triangles[i].v0, scene.triangles[i].v1, scene.triangles[i].v2}) {
            require(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z),
                    "octree: triangle " + std::to_string(i) + " has a non-finite vertex");
            refs[i].box.grow(v);
        }
        refs[i].prim = uint32_t(i);
        bounds.grow(refs[i].box);
    }
    OctreeBuilder b(scene, config);
    b.root_area = std::max(half_area(bounds), 1e-300);
    b.nodes.resize(1);
    b.build(0, bounds, refs, 0, 1.0);

    AccelImage image;
    image.kind = "octree";
    image.bounds = bounds;
    image.params = root_cell_json(bounds);
    Region& nodes = image.add_region<OctNode>("nodes", DataKind::node, b.nodes.size());
    std::copy(b.nodes.begin(), b.nodes.end(), nodes.records<OctNode>());
    Region& list = image.add_region<uint32_t>("prim_refs", DataKind::prim_ref, b.list.size());
    std::copy(b.list.begin(), b.list.end(), list.records<uint32_t>());
    HwTriangle* tris = image.add_region<HwTriangle>("triangles", DataKind::triangle, n).records<HwTriangle>();
    for (size_t i = 0; i < n; ++i) tris[i] = make_hw_triangle(scene, uint32_t(i));
    image.place_regions();
    const double total = double(b.list.size());
    image.stats = {{"builder", "adaptive"},
                   {"width", 8},
                   {"node_bytes", sizeof(OctNode)},
                   {"triangle_bytes", sizeof(HwTriangle)},
                   {"nodes", b.nodes.size()},
                   {"leaves", b.leaves},
                   {"max_depth", b.deepest},
                   {"references", b.list.size()},
                   {"references_per_triangle", total / double(n)},
                   {"avg_leaf_size", b.leaves ? total / double(b.leaves) : 0.0},
                   {"max_leaf_size", b.max_leaf},
                   {"sah_cost", b.sah},
                   {"build_work", b.work()},  // references clipped or listed, against its limit
                   {"build_work_limit", b.work_limit()}};
    return image;
}

}  // namespace rtsim
