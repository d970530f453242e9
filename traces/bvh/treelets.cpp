#include "traces/bvh/treelets.h"

#include <algorithm>
#include <limits>
#include <queue>

#include "traces/common/error.h"

namespace rtsim {

namespace {

constexpr uint32_t kNone = 0xFFFFFFFFu;

bool interior(const HwNode& n, int c) { return n.child_count[c] == 0; }

float half_area(const HwNode& parent, int c) {
    float ex = parent.hi(c, 0) - parent.lo(c, 0), ey = parent.hi(c, 1) - parent.lo(c, 1),
          ez = parent.hi(c, 2) - parent.lo(c, 2);
    return ex * ey + ey * ez + ez * ex;
}

/// Surface area of every node's box (from its parent's child slot; the root gets +inf).
std::vector<float> node_areas(const std::vector<HwNode>& nodes) {
    std::vector<float> area(nodes.size(), 0.0f);
    if (!area.empty()) area[0] = std::numeric_limits<float>::infinity();
    for (const HwNode& n : nodes)
        for (int c = 0; c < 2; ++c)
            if (interior(n, c)) area[n.child_ref[c]] = half_area(n, c);
    return area;
}

struct Candidate {
    float area;
    uint32_t node;
    bool operator<(const Candidate& o) const { return area < o.area || (area == o.area && node > o.node); }
};

}  // namespace

uint64_t node_footprint(const HwNode& node) {
    uint64_t bytes = sizeof(HwNode);
    for (int c = 0; c < 2; ++c)
        if (node.child_count[c] != 0 && node.child_count[c] != kEmptyChild)
            bytes += uint64_t(node.child_count[c]) * sizeof(HwTriangle);
    return bytes;
}

namespace {

/// Bytes of every node's whole subtree (children have larger indices: depth-first layout, so
/// one backwards pass suffices).
std::vector<uint64_t> subtree_bytes(const std::vector<HwNode>& nodes) {
    std::vector<uint64_t> bytes(nodes.size(), 0);
    for (size_t i = nodes.size(); i-- > 0;) {
        bytes[i] = node_footprint(nodes[i]);
        for (int c = 0; c < 2; ++c) {
            if (!interior(nodes[i], c)) continue;
            require(nodes[i].child_ref[c] > i, "treelets: node " + std::to_string(i) + " has a child before it");
            bytes[i] += bytes[nodes[i].child_ref[c]];
        }
    }
    return bytes;
}

/// Puts a node's whole subtree into treelet `id`.
void take_subtree(const std::vector<HwNode>& nodes, uint32_t root, uint32_t id, TreeletPartition* p,
                  TreeletInfo* info) {
    std::vector<uint32_t> stack{root};
    while (!stack.empty()) {
        uint32_t n = stack.back();
        stack.pop_back();
        p->node_treelet[n] = id;
        ++info->nodes;
        info->bytes += node_footprint(nodes[n]);
        for (int c = 0; c < 2; ++c)
            if (interior(nodes[n], c)) stack.push_back(nodes[n].child_ref[c]);
    }
}

/// Left-over subtrees smaller than the budget are packed together (first fit, largest first)
/// instead of each making a tiny treelet; larger ones start treelets of their own.
void pack_left_overs(const std::vector<HwNode>& nodes, const std::vector<uint64_t>& subtree,
                     std::vector<uint32_t> left_over, uint32_t depth, TreeletPartition* p,
                     std::queue<std::pair<uint32_t, uint32_t>>* roots) {
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
        for (uint32_t t : packs)
            if (p->treelets[t].bytes + subtree[n] <= p->budget_bytes) {
                target = t;
                break;
            }
        if (target == kNone) {
            target = uint32_t(p->treelets.size());
            p->treelets.push_back(TreeletInfo{n, 0, 0, depth + 1});
            packs.push_back(target);
        }
        take_subtree(nodes, n, target, p, &p->treelets[target]);
    }
}

}  // namespace

TreeletPartition partition_treelets(const std::vector<HwNode>& nodes, uint32_t budget_bytes) {
    require(budget_bytes >= sizeof(HwNode), "treelet budget must be at least one node (64 bytes)");
    require(!nodes.empty(), "cannot partition an empty BVH into treelets");
    TreeletPartition p;
    p.budget_bytes = budget_bytes;
    p.node_treelet.assign(nodes.size(), kNone);
    const std::vector<float> area = node_areas(nodes);
    const std::vector<uint64_t> subtree = subtree_bytes(nodes);
    // Treelet roots wait in a FIFO with the depth of the treelet they start.
    std::queue<std::pair<uint32_t, uint32_t>> roots;
    roots.push({0, 0});
    while (!roots.empty()) {
        auto [root, depth] = roots.front();
        roots.pop();
        const uint32_t id = uint32_t(p.treelets.size());
        TreeletInfo info{root, 0, 0, depth};
        std::priority_queue<Candidate> frontier;
        frontier.push({area[root], root});
        std::vector<uint32_t> left_over;  // frontier nodes that did not fit
        while (!frontier.empty()) {
            const uint32_t n = frontier.top().node;
            frontier.pop();
            if (info.bytes + subtree[n] <= budget_bytes) {
                take_subtree(nodes, n, id, &p, &info);  // the whole subtree fits: take it
                continue;
            }
            if (info.nodes > 0 && info.bytes + node_footprint(nodes[n]) > budget_bytes) {
                left_over.push_back(n);
                continue;
            }
            p.node_treelet[n] = id;
            ++info.nodes;
            info.bytes += node_footprint(nodes[n]);
            for (int c = 0; c < 2; ++c)
                if (interior(nodes[n], c)) frontier.push({area[nodes[n].child_ref[c]], nodes[n].child_ref[c]});
        }
        p.treelets.push_back(info);
        pack_left_overs(nodes, subtree, std::move(left_over), depth, &p, &roots);
    }
    return p;
}

void check_treelet_partition(const std::vector<HwNode>& nodes, const TreeletPartition& p) {
    require(p.node_treelet.size() == nodes.size(), "treelets: node_treelet has the wrong size");
    std::vector<uint32_t> counts(p.treelets.size(), 0);
    std::vector<uint64_t> bytes(p.treelets.size(), 0);
    for (size_t n = 0; n < nodes.size(); ++n) {
        const uint32_t t = p.node_treelet[n];
        require(t < p.treelets.size(), "treelets: node " + std::to_string(n) + " is in no valid treelet");
        ++counts[t];
        bytes[t] += node_footprint(nodes[n]);
    }
    // A treelet is one top-down grown piece plus, possibly, whole subtrees packed with it: every
    // node whose parent lies in another treelet is the treelet's root or the top of a subtree
    // that lies entirely in this treelet.
    std::vector<uint32_t> parent(nodes.size(), kNone);
    for (size_t n = 0; n < nodes.size(); ++n)
        for (int c = 0; c < 2; ++c)
            if (interior(nodes[n], c)) parent[nodes[n].child_ref[c]] = uint32_t(n);
    for (size_t n = 0; n < nodes.size(); ++n) {
        const uint32_t t = p.node_treelet[n];
        if (n == p.treelets[t].root || parent[n] == kNone || p.node_treelet[parent[n]] == t) continue;
        std::vector<uint32_t> stack{uint32_t(n)};
        while (!stack.empty()) {
            uint32_t k = stack.back();
            stack.pop_back();
            require(p.node_treelet[k] == t, "treelets: node " + std::to_string(k) + " leaves the subtree of node " +
                                                std::to_string(n) + " packed into treelet " + std::to_string(t));
            for (int c = 0; c < 2; ++c)
                if (interior(nodes[k], c)) stack.push_back(nodes[k].child_ref[c]);
        }
    }
    for (size_t t = 0; t < p.treelets.size(); ++t) {
        const TreeletInfo& info = p.treelets[t];
        require(p.node_treelet[info.root] == t, "treelets: root of treelet " + std::to_string(t) + " is not in it");
        require(counts[t] == info.nodes && bytes[t] == info.bytes,
                "treelets: treelet " + std::to_string(t) + " node or byte count does not add up");
        require(info.bytes <= p.budget_bytes || info.nodes == 1,
                "treelets: treelet " + std::to_string(t) + " has " + std::to_string(info.bytes) +
                    " bytes, over the budget of " + std::to_string(p.budget_bytes));
    }
}

}  // namespace rtsim
