// The kd-tree builder (kdtree.h): Wald & Havran 2006, "On building fast kd-trees for ray tracing,
// and on doing that in O(N log N)" (RT 2006). Each reference (the part of a triangle inside the
// current cell) gives per axis a start and an end event at its box's bounds, or one planar event
// when the box is flat on that axis. The events are sorted once, at the root; at each node one
// sweep per axis prices every candidate plane with the SAH (section 4, including the planar
// triangles' side and the empty-space bonus lambda), the references are classified against the
// chosen plane in one pass, the events of those wholly on one side are kept in order, and those
// straddling the plane are clipped to each child cell ("perfect splits", section 3.2; clipping in
// double, conservative: traces/bvh/sbvh_clip.h) and their few new events sorted and merged in.
// Every step is linear in the node's events, so the build is O(N log N).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "traces/accel/kdtree/kdtree.h"
#include "traces/bvh/build_tree.h"
#include "traces/bvh/sbvh_clip.h"
#include "traces/common/build_budget.h"
#include "traces/common/error.h"
#include "traces/scene/scene.h"

namespace rtsim {
namespace {

enum EventType : uint32_t { kEnd = 0, kPlanar = 1, kStart = 2 };

/// An event: position and (reference << 2 | type). Ordered by position, then end < planar <
/// start (the sweep counts ends before a plane and starts after it), then reference.
struct Event {
    float pos;
    uint32_t code;
    uint32_t ref() const { return code >> 2; }
    uint32_t type() const { return code & 3u; }
    bool operator<(const Event& o) const {
        return pos < o.pos || (pos == o.pos && (type() < o.type() || (type() == o.type() && code < o.code)));
    }
};

struct Events {
    std::vector<Event> axis[3];
    size_t refs() const {  // one start or planar event per reference on each axis
        size_t n = 0;
        for (const Event& e : axis[0]) n += e.type() != kEnd;
        return n;
    }
};

enum Side : uint8_t { kBoth = 0, kLeftOnly = 1, kRightOnly = 2 };

struct Split {
    bool valid = false;
    int axis = 0;
    float pos = 0.0f;
    bool planar_left = true;  ///< triangles lying in the plane go left
    double cost = 0.0;
};

double half_area(const Aabb& b) {
    const double x = double(b.hi.x) - b.lo.x, y = double(b.hi.y) - b.lo.y, z = double(b.hi.z) - b.lo.z;
    return x * y + y * z + z * x;
}

/// References a build may sweep (each node's events, summed over the nodes), per triangle and at
/// least. Ordinary scenes take 15-43 per triangle (docs/validation.md, "third round"); a
/// fan of triangles sharing a vertex keeps every triangle in every cell around that vertex, so
/// the SAH splits it down to the depth limit (800 triangles: 24 s and 12,800 references each).
constexpr double kKdWorkPerTriangle = 512.0;
constexpr double kKdMinWork = double(1u << 23);

class KdBuilder {
public:
    KdBuilder(const Scene& scene, const KdConfig& config) : m_scene(scene), m_c(config) {}
    KdTreeBuild run();

private:
    /// Builds the node over `cell`; `share`: its part of the root's references (the leaves'
    /// shares add up to 1, so the work over the share finished extrapolates the whole build).
    uint32_t build(Events& ev, const Aabb& cell, uint32_t depth, double share);
    /// Before `n` references are swept: refuses a build whose work (so far, or extrapolated from
    /// the share finished) passes its limit, or whose memory would not fit.
    void check_work(uint64_t n);
    Split find_split(const Events& ev, const Aabb& cell, size_t n) const;
    double sah(const Aabb& cell, double area, int axis, float pos, size_t nl, size_t nr) const;
    void divide(Events& ev, const Split& s, Events* left, Events* right);
    void add_events(uint32_t ref, Events* out) const;
    void make_leaf(const Events& ev, uint32_t index);
    uint32_t add_ref(const Aabb& box, uint32_t prim);

    const Scene& m_scene;
    KdConfig m_c;
    uint32_t m_max_depth = 0;
    double m_root_area = 1.0;
    std::vector<Aabb> m_box;     ///< every reference's box (the pool grows as straddlers are clipped)
    std::vector<uint32_t> m_prim;
    std::vector<uint8_t> m_side;
    KdTreeBuild m_out;
    // What the manifest records.
    uint64_t m_leaves = 0, m_empty_leaves = 0, m_max_leaf = 0, m_depth = 0, m_clipped = 0;
    double m_sah = 0.0, m_kd_cost = 0.0;
    double m_work = 0.0, m_done = 0.0, m_work_limit = kKdMinWork;
};

void KdBuilder::check_work(uint64_t n) {
    m_work += double(n);
    const double share = std::max(m_done, 1e-12);
    // Past a quarter of the budget (more than any ordinary scene's whole build) the share
    // finished is a fair sample, so the extrapolated whole must fit too: refused early.
    const bool over = m_work > m_work_limit || (m_work > m_work_limit / 4 && m_work / share > m_work_limit);
    char text[600];
    const double tris = double(m_scene.triangles.size());
    if (over) {
        std::snprintf(text, sizeof text,
                      "kdtree (max_depth=%u, empty_bonus=%g): the build would sweep about %.3g references (%.3g per "
                      "triangle; %.3g so far for %.2g%% of the scene), more than the %.3g a build of %.0f triangles "
                      "may; many triangles meeting in one point or line stay together in every cell around it, so "
                      "the SAH splits them down to the depth limit: lower max_depth (--build-set max_depth=12), or "
                      "use another structure",
                      m_max_depth, double(m_c.empty_bonus), m_work / share, m_work / share / tris, m_work,
                      100.0 * m_done, m_work_limit, tris);
        throw Error(text);
    }
    // The reference pool, the node and list arrays held now.
    const double bytes = double(m_box.size()) * (sizeof(Aabb) + 5.0) + double(m_out.nodes.size()) * sizeof(KdNode) +
                         double(m_out.refs.size()) * 4.0 + double(n) * 6.0 * sizeof(Event);
    std::snprintf(text, sizeof text, "%zu references pooled, %zu nodes, %zu listed", m_box.size(), m_out.nodes.size(),
                  m_out.refs.size());
    check_build_memory(bytes, "kdtree (max_depth=" + std::to_string(m_max_depth) + ")", text,
                       "lower max_depth (--build-set max_depth=12)");
}

uint32_t KdBuilder::add_ref(const Aabb& box, uint32_t prim) {
    m_box.push_back(box);
    m_prim.push_back(prim);
    m_side.push_back(kBoth);
    return uint32_t(m_box.size() - 1);
}

void KdBuilder::add_events(uint32_t ref, Events* out) const {
    const Aabb& b = m_box[ref];
    for (int a = 0; a < 3; ++a) {
        if (b.lo[a] == b.hi[a]) {
            out->axis[a].push_back(Event{b.lo[a], ref << 2 | kPlanar});
        } else {
            out->axis[a].push_back(Event{b.lo[a], ref << 2 | kStart});
            out->axis[a].push_back(Event{b.hi[a], ref << 2 | kEnd});
        }
    }
}

double KdBuilder::sah(const Aabb& cell, double area, int axis, float pos, size_t nl, size_t nr) const {
    Aabb l = cell, r = cell;
    l.hi[axis] = pos;
    r.lo[axis] = pos;
    // The empty-space bonus (the paper's lambda): cutting off empty space is favoured.
    const double lambda = (nl == 0 || nr == 0) ? 1.0 - double(m_c.empty_bonus) : 1.0;
    return lambda * (m_c.traversal_cost + m_c.intersection_cost * (half_area(l) / area * double(nl) +
                                                                     half_area(r) / area * double(nr)));
}

Split KdBuilder::find_split(const Events& ev, const Aabb& cell, size_t n) const {
    Split best;
    const double area = half_area(cell);
    if (!(area > 0.0)) return best;
    for (int k = 0; k < 3; ++k) {
        const std::vector<Event>& e = ev.axis[k];
        size_t nl = 0, nr = n;
        for (size_t i = 0; i < e.size();) {
            const float p = e[i].pos;
            size_t ends = 0, planar = 0, starts = 0;
            while (i < e.size() && e[i].pos == p && e[i].type() == kEnd) ++ends, ++i;
            while (i < e.size() && e[i].pos == p && e[i].type() == kPlanar) ++planar, ++i;
            while (i < e.size() && e[i].pos == p && e[i].type() == kStart) ++starts, ++i;
            nr -= planar + ends;
            // Only planes strictly inside the cell: a plane on its boundary would cut nothing.
            if (p > cell.lo[k] && p < cell.hi[k]) {
                const double left = sah(cell, area, k, p, nl + planar, nr);
                const double right = sah(cell, area, k, p, nl, nr + planar);
                const double cost = std::min(left, right);
                if (!best.valid || cost < best.cost) best = Split{true, k, p, left <= right, cost};
            }
            nl += starts + planar;
        }
    }
    return best;
}

void KdBuilder::divide(Events& ev, const Split& s, Events* left, Events* right) {
    // Classify (the paper's algorithm 5): every reference Both, then by its events on the axis.
    for (const Event& e : ev.axis[s.axis]) m_side[e.ref()] = kBoth;
    for (const Event& e : ev.axis[s.axis]) {
        const uint32_t r = e.ref();
        if (e.type() == kEnd && e.pos <= s.pos) m_side[r] = kLeftOnly;
        else if (e.type() == kStart && e.pos >= s.pos) m_side[r] = kRightOnly;
        else if (e.type() == kPlanar)
            m_side[r] = e.pos < s.pos || (e.pos == s.pos && s.planar_left) ? kLeftOnly : kRightOnly;
    }
    // Events of one-sided references keep their order; straddlers are clipped to each side.
    std::vector<uint32_t> straddlers;
    for (const Event& e : ev.axis[s.axis])
        if (m_side[e.ref()] == kBoth && e.type() == kStart) straddlers.push_back(e.ref());
    for (int a = 0; a < 3; ++a) {
        for (const Event& e : ev.axis[a]) {
            const uint8_t side = m_side[e.ref()];
            if (side == kLeftOnly) left->axis[a].push_back(e);
            else if (side == kRightOnly) right->axis[a].push_back(e);
        }
        std::vector<Event>().swap(ev.axis[a]);  // the parent's events are no longer needed
    }
    Events new_left, new_right;
    for (uint32_t r : straddlers) {
        Aabb l = m_box[r], rb = m_box[r];
        const Triangle& tri = m_scene.triangles[m_prim[r]];
        if (m_c.clip) {
            ClippedTriangle(tri, m_box[r]).split(s.axis, s.pos, &l, &rb);
        } else {
            l.hi[s.axis] = s.pos;
            rb.lo[s.axis] = s.pos;
        }
        m_clipped += 1;
        const uint32_t prim = m_prim[r];
        if (!l.empty()) add_events(add_ref(l, prim), &new_left);
        if (!rb.empty()) add_events(add_ref(rb, prim), &new_right);
    }
    for (int a = 0; a < 3; ++a) {
        const std::pair<std::vector<Event>*, std::vector<Event>*> sides[2] = {{&left->axis[a], &new_left.axis[a]},
                                                                              {&right->axis[a], &new_right.axis[a]}};
        for (const auto& [events, fresh] : sides) {
            std::sort(fresh->begin(), fresh->end());
            const size_t mid = events->size();
            events->insert(events->end(), fresh->begin(), fresh->end());
            std::inplace_merge(events->begin(), events->begin() + std::ptrdiff_t(mid), events->end());
        }
    }
}

void KdBuilder::make_leaf(const Events& ev, uint32_t index) {
    std::vector<uint32_t> prims;
    for (const Event& e : ev.axis[0])
        if (e.type() != kEnd) prims.push_back(m_prim[e.ref()]);
    std::sort(prims.begin(), prims.end());
    require(prims.size() <= KdNode::kMaxIndex && m_out.refs.size() + prims.size() < (1ull << 32),
            "kdtree: too many references for the layout");
    m_out.nodes[index] = KdNode::make_leaf(uint32_t(m_out.refs.size()), uint32_t(prims.size()));
    m_out.refs.insert(m_out.refs.end(), prims.begin(), prims.end());
    m_leaves += 1;
    m_empty_leaves += prims.empty();
    m_max_leaf = std::max<uint64_t>(m_max_leaf, prims.size());
}

uint32_t KdBuilder::build(Events& ev, const Aabb& cell, uint32_t depth, double share) {
    check_work(ev.refs());
    const uint32_t index = uint32_t(m_out.nodes.size());
    require(index < KdNode::kMaxIndex, "kdtree: more than 2^30 nodes");
    m_out.nodes.push_back(KdNode{});
    m_depth = std::max<uint64_t>(m_depth, depth);
    const size_t n = ev.refs();
    const double weight = half_area(cell) / m_root_area;
    const Split s = depth < m_max_depth && n > 0 ? find_split(ev, cell, n) : Split{};
    // A leaf unless a split is cheaper than testing every reference here.
    if (!s.valid || !(s.cost < double(m_c.intersection_cost) * double(n))) {
        m_sah += weight * double(n);
        m_kd_cost += weight * double(m_c.intersection_cost) * double(n);
        m_done += share;
        make_leaf(ev, index);
        return index;
    }
    m_sah += weight;
    m_kd_cost += weight * double(m_c.traversal_cost);
    Events left, right;
    divide(ev, s, &left, &right);
    Aabb lc = cell, rc = cell;
    lc.hi[s.axis] = s.pos;
    rc.lo[s.axis] = s.pos;
    // The left subtree's clipped references are garbage once it is built (the right side's
    // events name only older ones): the pool shrinks back, so it holds one root path's worth.
    const size_t pool = m_box.size();
    const double nl = double(left.refs()), nr = double(right.refs());
    const double left_share = nl + nr > 0 ? share * nl / (nl + nr) : share / 2;
    build(left, lc, depth + 1, left_share);
    left = Events{};
    m_box.resize(pool), m_prim.resize(pool), m_side.resize(pool);
    const uint32_t above = build(right, rc, depth + 1, share - left_share);
    m_out.nodes[index] = KdNode::interior(s.axis, s.pos, above);
    return index;
}

KdTreeBuild KdBuilder::run() {
    const size_t n = m_scene.triangles.size();
    require(n > 0, "kdtree: the scene has no triangles");
    require(n < (size_t(1) << 30), "kdtree: too many triangles (>= 2^30)");
    require(m_c.max_depth <= kKdMaxDepth, "kdtree: max_depth must be at most " + std::to_string(kKdMaxDepth));
    m_max_depth = m_c.max_depth ? m_c.max_depth
                                : std::min<uint32_t>(kKdMaxDepth, uint32_t(8.0 + 1.3 * std::log2(double(n))));
    Events root;
    for (size_t i = 0; i < n; ++i) {
        const Triangle& t = m_scene.triangles[i];
        Aabb box;
        for (const Vec3& v : {t.v0, t.v1, t.v2}) {
            require(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z),
                    "kdtree: triangle " + std::to_string(i) + " has a non-finite vertex");
            box.grow(v);
        }
        m_out.bounds.grow(box);
        add_events(add_ref(box, uint32_t(i)), &root);
    }
    for (auto& axis : root.axis) std::sort(axis.begin(), axis.end());
    m_root_area = std::max(half_area(m_out.bounds), 1e-300);
    m_work_limit = std::max(kKdMinWork, kKdWorkPerTriangle * double(n));
    build(root, m_out.bounds, 0, 1.0);
    const double refs = double(m_out.refs.size());
    m_out.stats = {{"builder", "sah"},
                   {"width", 2},
                   {"node_bytes", sizeof(KdNode)},
                   {"triangle_bytes", sizeof(HwTriangle)},
                   {"nodes", m_out.nodes.size()},
                   {"leaves", m_leaves},
                   {"empty_leaves", m_empty_leaves},
                   {"max_depth", m_depth},
                   {"depth_limit", m_max_depth},
                   {"references", m_out.refs.size()},
                   {"references_per_triangle", refs / double(n)},
                   {"avg_leaf_size", m_leaves > m_empty_leaves ? refs / double(m_leaves - m_empty_leaves) : 0.0},
                   {"max_leaf_size", m_max_leaf},
                   {"clipped_references", m_clipped},
                   {"sah_cost", m_sah},
                   {"kd_sah_cost", m_kd_cost},
                   {"build_work", m_work},  // references swept, against its limit
                   {"build_work_limit", m_work_limit}};
    return std::move(m_out);
}

}  // namespace

KdTreeBuild build_kdtree(const Scene& scene, const KdConfig& config) { return KdBuilder(scene, config).run(); }

}  // namespace rtsim
