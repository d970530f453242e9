#include "traces/accel/locality.h"

#include <algorithm>
#include <limits>
#include <queue>
#include <string>

#include "traces/common/error.h"

namespace rtsim {

namespace {

constexpr uint32_t kNone = 0xFFFFFFFFu;

struct Candidate {
    float area;
    uint32_t node;
    bool operator<(const Candidate& o) const { return area < o.area || (area == o.area && node > o.node); }
};

template <class F>
void for_children(const LocalityTree& t, uint32_t n, F&& f) {
    for (uint32_t i = t.child_begin[n]; i < t.child_begin[n + 1]; ++i) f(t.children[i]);
}

/// Bytes of every node's whole subtree (children have larger indices: one backwards pass).
std::vector<uint64_t> subtree_bytes(const LocalityTree& t) {
    std::vector<uint64_t> bytes(t.size(), 0);
    for (size_t i = t.size(); i-- > 0;) {
        bytes[i] = t.bytes[i];
        for_children(t, uint32_t(i), [&](uint32_t c) {
            require(c > i, "treelets: node " + std::to_string(i) + " has a child before it");
            bytes[i] += bytes[c];
        });
    }
    return bytes;
}

/// Puts a node's whole subtree into treelet `id`.
void take_subtree(const LocalityTree& t, uint32_t root, uint32_t id, LocalityPartition* p, TreeletInfo* info) {
    std::vector<uint32_t> stack{root};
    while (!stack.empty()) {
        uint32_t n = stack.back();
        stack.pop_back();
        p->group_of[n] = id;
        ++info->nodes;
        info->bytes += t.bytes[n];
        for_children(t, n, [&](uint32_t c) { stack.push_back(c); });
    }
}

/// Left-over subtrees smaller than the budget are packed together (first fit, largest first)
/// instead of each making a tiny treelet; larger ones start treelets of their own.
void pack_left_overs(const LocalityTree& t, const std::vector<uint64_t>& subtree, std::vector<uint32_t> left_over,
                     uint32_t depth, LocalityPartition* p, std::queue<std::pair<uint32_t, uint32_t>>* roots) {
    std::sort(left_over.begin(), left_over.end(), [&](uint32_t a, uint32_t b) {
        return subtree[a] > subtree[b] || (subtree[a] == subtree[b] && a < b);
    });
    std::vector<uint32_t> packs;  // treelet ids opened for packing
    for (uint32_t n : left_over) {
        if (subtree[n] > p->budget_bytes) {
            roots->push({n, depth + 1});
            continue;
        }
        uint32_t target = kNone;
        for (uint32_t k : packs)
            if (p->treelets[k].bytes + subtree[n] <= p->budget_bytes) {
                target = k;
                break;
            }
        if (target == kNone) {
            target = uint32_t(p->treelets.size());
            p->treelets.push_back(TreeletInfo{n, 0, 0, depth + 1});
            packs.push_back(target);
        }
        take_subtree(t, n, target, p, &p->treelets[target]);
    }
}

}  // namespace

void LocalityTree::add_node(uint64_t node_bytes, float node_area) {
    if (child_begin.empty()) child_begin.push_back(0);
    else child_begin.push_back(uint32_t(children.size()));
    bytes.push_back(node_bytes);
    area.push_back(node_area);
}

void LocalityTree::add_child(uint32_t child) { children.push_back(child); }

void LocalityTree::finish() { child_begin.push_back(uint32_t(children.size())); }

LocalityPartition partition_tree(const LocalityTree& t, uint64_t budget_bytes) {
    require(t.size() > 0, "cannot partition an empty tree into treelets");
    require(t.child_begin.size() == size_t(t.size()) + 1, "treelets: locality tree not finished");
    LocalityPartition p;
    p.budget_bytes = budget_bytes;
    p.group_of.assign(t.size(), kNone);
    const std::vector<uint64_t> subtree = subtree_bytes(t);
    // Treelet roots wait in a FIFO with the depth of the treelet they start.
    std::queue<std::pair<uint32_t, uint32_t>> roots;
    roots.push({0, 0});
    while (!roots.empty()) {
        auto [root, depth] = roots.front();
        roots.pop();
        const uint32_t id = uint32_t(p.treelets.size());
        TreeletInfo info{root, 0, 0, depth};
        std::priority_queue<Candidate> frontier;
        frontier.push({t.area[root], root});
        std::vector<uint32_t> left_over;  // frontier nodes that did not fit
        while (!frontier.empty()) {
            const uint32_t n = frontier.top().node;
            frontier.pop();
            if (info.bytes + subtree[n] <= budget_bytes) {
                take_subtree(t, n, id, &p, &info);  // the whole subtree fits: take it
                continue;
            }
            if (info.nodes > 0 && info.bytes + t.bytes[n] > budget_bytes) {
                left_over.push_back(n);
                continue;
            }
            p.group_of[n] = id;
            ++info.nodes;
            info.bytes += t.bytes[n];
            for_children(t, n, [&](uint32_t c) { frontier.push({t.area[c], c}); });
        }
        p.treelets.push_back(info);
        pack_left_overs(t, subtree, std::move(left_over), depth, &p, &roots);
    }
    p.root_group = p.group_of[0];
    return p;
}

void check_tree_partition(const LocalityTree& t, const LocalityPartition& p) {
    require(p.group_of.size() == t.size(), "treelets: group_of has the wrong size");
    std::vector<uint32_t> counts(p.treelets.size(), 0);
    std::vector<uint64_t> bytes(p.treelets.size(), 0);
    for (uint32_t n = 0; n < t.size(); ++n) {
        const uint32_t k = p.group_of[n];
        require(k < p.treelets.size(), "treelets: node " + std::to_string(n) + " is in no valid treelet");
        ++counts[k];
        bytes[k] += t.bytes[n];
    }
    // A treelet is one top-down grown piece plus, possibly, whole subtrees packed with it: every
    // node whose parent lies in another treelet is the treelet's root or the top of a subtree
    // that lies entirely in this treelet.
    std::vector<uint32_t> parent(t.size(), kNone);
    for (uint32_t n = 0; n < t.size(); ++n) for_children(t, n, [&](uint32_t c) { parent[c] = n; });
    for (uint32_t n = 0; n < t.size(); ++n) {
        const uint32_t k = p.group_of[n];
        if (n == p.treelets[k].root || parent[n] == kNone || p.group_of[parent[n]] == k) continue;
        std::vector<uint32_t> stack{n};
        while (!stack.empty()) {
            uint32_t m = stack.back();
            stack.pop_back();
            require(p.group_of[m] == k, "treelets: node " + std::to_string(m) + " leaves the subtree of node " +
                                            std::to_string(n) + " packed into treelet " + std::to_string(k));
            for_children(t, m, [&](uint32_t c) { stack.push_back(c); });
        }
    }
    for (size_t k = 0; k < p.treelets.size(); ++k) {
        const TreeletInfo& info = p.treelets[k];
        require(p.group_of[info.root] == k, "treelets: root of treelet " + std::to_string(k) + " is not in it");
        require(counts[k] == info.nodes && bytes[k] == info.bytes,
                "treelets: treelet " + std::to_string(k) + " node or byte count does not add up");
        require(info.bytes <= p.budget_bytes || info.nodes == 1,
                "treelets: treelet " + std::to_string(k) + " has " + std::to_string(info.bytes) +
                    " bytes, over the budget of " + std::to_string(p.budget_bytes));
    }
}

}  // namespace rtsim
