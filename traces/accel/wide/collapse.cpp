// Collapsing a binary build tree into a wide tree (wide_tree.h): the SAH-optimal dynamic
// programme of Ylitie, Karras & Laine 2017 ("Efficient incoherent ray traversal on GPUs through
// compressed wide BVHs", HPG, section 3.1) and, for comparison, the greedy largest-area child
// expansion of Wald, Benthin & Boulos 2008 / Ernst & Greiner 2008.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "traces/accel/wide/wide_tree.h"
#include "traces/common/error.h"

namespace rtsim {
namespace {

constexpr double kInfCost = std::numeric_limits<double>::infinity();

/// Half the surface area in double (float products overflow beyond about 1e19).
double area_of(const Aabb& box) {
    if (box.empty()) return 0.0;
    const glm::dvec3 e = glm::dvec3(box.hi) - glm::dvec3(box.lo);
    return e.x * e.y + e.y * e.z + e.z * e.x;
}

/// Shared by both collapses: the output tree and the binary subtree helpers.
class Collapser {
public:
    Collapser(const BuildTree& tree, const CollapseConfig& c) : m_in(tree), m_c(c) {
        m_out.width = c.width;
        m_out.nodes.reserve(tree.nodes.size() / size_t(std::max(1, c.width - 1)) + 1);
        m_out.prims.reserve(tree.prim_ids.size());
    }
    WideBuildTree take() { return std::move(m_out); }

protected:
    Aabb box_of(uint32_t n) const {
        const BuildNode& b = m_in.nodes[n];
        if (b.is_leaf()) return b.box;
        Aabb u = m_in.nodes[b.first].box;
        u.grow(m_in.nodes[b.first + 1].box);
        return u;
    }
    /// A leaf child holding every primitive of binary subtree n, in left-to-right leaf order.
    WideBuildChild leaf_of(uint32_t n) {
        WideBuildChild c;
        c.box = box_of(n);
        c.first = uint32_t(m_out.prims.size());
        std::vector<uint32_t>& stack = m_leaf_stack;
        stack.assign(1, n);
        while (!stack.empty()) {
            const BuildNode& b = m_in.nodes[stack.back()];
            stack.pop_back();
            if (b.is_leaf()) {
                m_out.prims.insert(m_out.prims.end(), m_in.prim_ids.begin() + b.first,
                                   m_in.prim_ids.begin() + b.first + b.count);
            } else {
                stack.insert(stack.end(), {b.first + 1, b.first});  // left popped first
            }
        }
        c.count = uint32_t(m_out.prims.size()) - c.first;
        return c;
    }
    /// Appends an empty wide node; returns its index.
    uint32_t new_node() {
        m_out.nodes.emplace_back();
        return uint32_t(m_out.nodes.size() - 1);
    }
    void add_child(uint32_t node, const WideBuildChild& c) {
        WideBuildNode& w = m_out.nodes[node];
        w.child[w.count++] = c;
        w.box.grow(c.box);
    }

    const BuildTree& m_in;
    const CollapseConfig& m_c;
    WideBuildTree m_out;
    std::vector<uint32_t> m_leaf_stack;  ///< leaf_of's scratch
};

/// Ylitie et al. 2017, section 3.1. cost(n, i) is the SAH cost of representing binary subtree n
/// as at most i child slots of the parent:
///   cost(n, 1) = min(leaf: A(n) * C_i * P(n) if P(n) <= leaf_max, interior: A(n) * C_t + dist(n, W))
///   cost(n, i) = min(dist(n, i), cost(n, i - 1)) for i > 1
///   dist(n, j) = min over k in 1..j-1 of cost(left, k) + cost(right, j - k)
/// Ties keep fewer slots and prefer leaves (fewer box tests, fewer steps).
///
/// The costs are solved in post-order with an explicit stack: a node's cost row is needed only
/// until its parent is solved, so the rows live on a stack as deep as the tree instead of in a
/// table over every node (8 doubles a node: tens of megabytes to allocate and miss in for a
/// large scene). Only the choices, which fill() reads top-down afterwards, are kept per node.
class DpCollapser : public Collapser {
public:
    using Collapser::Collapser;

    void run() {
        // solve() writes every reachable node's entries before fill() reads them: no initial fill.
        m_choice.reset(new uint8_t[m_in.nodes.size() * size_t(m_c.width)]);
        m_dist_k.reset(new uint8_t[m_in.nodes.size()]);
        solve_all();
        const uint32_t root = new_node();
        if (m_in.nodes[0].is_leaf()) add_child(root, leaf_of(0));
        else fill(root, 0);
    }

private:
    /// cost(n, i) for i = 1..W (index i - 1) and the subtree's triangle count.
    struct Row {
        double cost[kMaxWideWidth];
        uint32_t tris;
    };

    uint8_t& choice(uint32_t n, uint32_t i) { return m_choice[size_t(n) * size_t(m_c.width) + (i - 1)]; }

    /// Every node reachable from the root, children before their parent.
    void solve_all() {
        struct Visit {
            uint32_t node;
            bool children_done;
        };
        std::vector<Visit> todo{{0, false}};
        std::vector<Row> rows;  // solved subtrees whose parent is not solved yet
        while (!todo.empty()) {
            Visit& top = todo.back();
            const BuildNode& b = m_in.nodes[top.node];
            if (!b.is_leaf() && !top.children_done) {
                top.children_done = true;
                todo.push_back({b.first + 1, false});
                todo.push_back({b.first, false});  // the left subtree is solved first
                continue;
            }
            const uint32_t n = top.node;
            todo.pop_back();
            if (b.is_leaf()) {
                rows.push_back(solve_leaf(n));
            } else {
                const Row r = rows.back();
                rows.pop_back();
                rows.back() = solve(n, rows.back(), r);
            }
        }
    }

    Row solve_leaf(uint32_t n) {
        const BuildNode& b = m_in.nodes[n];
        if (b.count > m_c.leaf_max)
            throw Error("collapse: binary leaf of " + std::to_string(b.count) +
                        " triangles above the wide leaf limit (split it first)");
        const double area = area_of(box_of(n));
        Row row;
        row.tris = b.count;
        for (uint32_t i = 1; i <= uint32_t(m_c.width); ++i) {
            row.cost[i - 1] = area * m_c.intersection_cost * b.count;
            choice(n, i) = 0;  // a leaf, whatever the slots
        }
        return row;
    }

    /// Interior node n from its children's rows.
    Row solve(uint32_t n, const Row& l, const Row& r) {
        const uint32_t width = uint32_t(m_c.width);
        const double area = area_of(box_of(n));
        Row row;
        row.tris = l.tris + r.tris;
        double dist[kMaxWideWidth + 1];
        uint8_t dist_k[kMaxWideWidth + 1] = {};
        for (uint32_t j = 2; j <= width; ++j) {
            dist[j] = kInfCost;
            for (uint32_t k = 1; k < j; ++k) {
                const double c = l.cost[k - 1] + r.cost[j - k - 1];
                if (c < dist[j]) dist[j] = c, dist_k[j] = uint8_t(k);
            }
        }
        m_dist_k[n] = dist_k[width];
        const double interior = area * m_c.traversal_cost + dist[width];
        const double leaf = row.tris <= m_c.leaf_max ? area * m_c.intersection_cost * row.tris : kInfCost;
        row.cost[0] = std::min(leaf, interior);
        choice(n, 1) = leaf <= interior ? 0 : 1;  // 0: leaf, 1: interior node
        for (uint32_t i = 2; i <= width; ++i) {
            const bool split = dist[i] < row.cost[i - 2];
            row.cost[i - 1] = split ? dist[i] : row.cost[i - 2];
            choice(n, i) = split ? dist_k[i] : 0;  // 0: as with i - 1 slots; k: k slots to the left
        }
        return row;
    }

    /// Wide node `node` gets binary node n's two subtrees as its (at most W) children.
    void fill(uint32_t node, uint32_t n) {
        const BuildNode& b = m_in.nodes[n];
        const uint32_t k = m_dist_k[n];
        forest(node, b.first, k);
        forest(node, b.first + 1, uint32_t(m_c.width) - k);
    }

    /// Binary subtree n as at most i children of wide node `node`.
    void forest(uint32_t node, uint32_t n, uint32_t i) {
        while (i > 1 && choice(n, i) == 0) --i;
        if (i > 1) {
            const uint32_t k = choice(n, i);
            forest(node, m_in.nodes[n].first, k);
            forest(node, m_in.nodes[n].first + 1, i - k);
            return;
        }
        if (m_in.nodes[n].is_leaf() || choice(n, 1) == 0) {
            add_child(node, leaf_of(n));
            return;
        }
        const uint32_t child = new_node();
        WideBuildChild c;
        c.node = child;
        fill(child, n);
        c.box = m_out.nodes[child].box;
        add_child(node, c);
    }

    std::unique_ptr<uint8_t[]> m_choice;
    std::unique_ptr<uint8_t[]> m_dist_k;
};

/// Wald et al. 2008: start from the binary node's two children and repeatedly replace the
/// interior child of largest surface area by its two children until the node is full.
class GreedyCollapser : public Collapser {
public:
    using Collapser::Collapser;

    void run() {
        const uint32_t root = new_node();
        if (m_in.nodes[0].is_leaf()) add_child(root, leaf_of(0));
        else fill(root, 0);
    }

private:
    void fill(uint32_t node, uint32_t n) {
        uint32_t open[kMaxWideWidth] = {m_in.nodes[n].first, m_in.nodes[n].first + 1};
        uint32_t count = 2;
        while (count < uint32_t(m_c.width)) {
            int best = -1;
            double best_area = -1.0;
            for (uint32_t i = 0; i < count; ++i) {
                if (m_in.nodes[open[i]].is_leaf()) continue;
                const double a = area_of(box_of(open[i]));
                if (a > best_area) best_area = a, best = int(i);
            }
            if (best < 0) break;
            const uint32_t f = m_in.nodes[open[best]].first;
            std::copy_backward(open + best + 1, open + count, open + count + 1);
            open[best] = f;
            open[best + 1] = f + 1;
            ++count;
        }
        for (uint32_t i = 0; i < count; ++i) {
            if (m_in.nodes[open[i]].is_leaf()) {
                add_child(node, leaf_of(open[i]));
                continue;
            }
            const uint32_t child = new_node();
            WideBuildChild c;
            c.node = child;
            fill(child, open[i]);
            c.box = m_out.nodes[child].box;
            add_child(node, c);
        }
    }
};

}  // namespace

WideBuildTree collapse_tree(const BuildTree& tree, const CollapseConfig& c) {
    require(c.width >= 2 && c.width <= kMaxWideWidth, "collapse: width must be in [2, 8]");
    require(c.leaf_max >= 1 && c.leaf_max <= kWideLeafMax, "collapse: leaf_max must be in [1, 3]");
    require(!tree.nodes.empty(), "collapse: empty build tree");
    if (c.method == Collapse::greedy) {
        for (const BuildNode& b : tree.nodes)
            if (b.is_leaf() && b.count > c.leaf_max)
                throw Error("collapse: binary leaf of " + std::to_string(b.count) +
                            " triangles above the wide leaf limit (split it first)");
        GreedyCollapser g(tree, c);
        g.run();
        return g.take();
    }
    DpCollapser d(tree, c);
    d.run();
    return d.take();
}

double wide_sah_cost(const WideBuildTree& tree, float traversal_cost, float intersection_cost) {
    if (tree.nodes.empty()) return 0.0;
    const double root = area_of(tree.nodes[0].box);
    auto weight = [root](const Aabb& b) { return root > 0.0 ? area_of(b) / root : 1.0; };
    double cost = 0.0;
    for (const WideBuildNode& n : tree.nodes) {
        cost += double(traversal_cost) * weight(n.box);
        for (uint32_t i = 0; i < n.count; ++i)
            if (n.child[i].is_leaf()) cost += double(intersection_cost) * n.child[i].count * weight(n.child[i].box);
    }
    return cost;
}

}  // namespace rtsim
