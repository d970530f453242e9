// validate_bvh_image: one depth-first walk from the root with an explicit stack, marking nodes
// and triangles as they are reached; then every node and triangle must have been reached once.
#include "traces/bvh/bvh_image_checks.h"

#include <cmath>

#include "traces/common/error.h"

namespace rtsim {
namespace {

/// Entries of the traversal stack (kTraversalStackSize in traces/isect/traversal.h, which this
/// library cannot include; tests/cpp/bvh/test_bvh_image_checks.cpp asserts they are equal).
constexpr uint32_t kStackEntries = 64;

class ImageChecker {
public:
    ImageChecker(const std::vector<HwNode>& nodes, const std::vector<HwTriangle>& triangles,
                 const std::string& source)
        : m_nodes(nodes), m_tris(triangles), m_source(source) {}

    void run() {
        if (m_nodes.empty()) throw Error(m_source + ": the BVH image has no nodes (section NODE is empty)");
        if (m_tris.empty())
            throw Error(m_source + ": the BVH image has no triangles (section TRIS is empty)");
        m_node_seen.assign(m_nodes.size(), 0);
        m_tri_seen.assign(m_tris.size(), 0);
        m_prim_seen.assign(m_tris.size(), 0);
        m_node_seen[0] = 1;
        m_stack.push_back({0, 0});
        while (!m_stack.empty()) {
            const Item item = m_stack.back();
            m_stack.pop_back();
            for (int slot = 0; slot < 2; ++slot) check_slot(item.node, slot, item.depth);
        }
        for (size_t i = 0; i < m_node_seen.size(); ++i)
            if (!m_node_seen[i])
                throw Error(m_source + ": BVH node " + std::to_string(i) + " is not reachable from the root");
        for (size_t t = 0; t < m_tri_seen.size(); ++t)
            if (!m_tri_seen[t])
                throw Error(m_source + ": BVH triangle " + std::to_string(t) + " belongs to no leaf");
    }

private:
    struct Item {
        uint32_t node;
        uint32_t depth;  ///< root at 0
    };

    [[noreturn]] void fail(uint32_t node, int slot, const std::string& what) const {
        throw Error(m_source + ": BVH node " + std::to_string(node) + " child " + std::to_string(slot) +
                    ": " + what);
    }

    bool box_has_nan(const HwNode& n, int slot) const {
        for (int a = 0; a < 3; ++a)
            if (std::isnan(n.lo(slot, a)) || std::isnan(n.hi(slot, a))) return true;
        return false;
    }

    void check_slot(uint32_t node, int slot, uint32_t depth) {
        const HwNode& n = m_nodes[node];
        const uint32_t count = n.child_count[slot], ref = n.child_ref[slot];
        if (count == kEmptyChild) return check_empty(node, slot);
        if (box_has_nan(n, slot)) fail(node, slot, "box has a NaN bound");
        if (count != 0) return check_leaf(node, slot, ref, count);
        // Interior child: a new node, one level deeper.
        if (ref == 0 || ref >= m_nodes.size())
            fail(node, slot, "child node index " + std::to_string(ref) + " out of range (1.." +
                                 std::to_string(m_nodes.size() - 1) + ")");
        if (m_node_seen[ref])
            fail(node, slot, "child node " + std::to_string(ref) +
                                 " is reached twice (a cycle or a shared subtree)");
        if (depth + 1 >= kStackEntries)
            fail(node, slot, "child node " + std::to_string(ref) + " at depth " + std::to_string(depth + 1) +
                                 " is deeper than the traversal stack allows (" +
                                 std::to_string(kStackEntries) + " entries)");
        m_node_seen[ref] = 1;
        m_stack.push_back({ref, depth + 1});
    }

    void check_empty(uint32_t node, int slot) const {
        const HwNode& n = m_nodes[node];
        if (node != 0 || slot != 1 || n.child_count[0] == 0 || n.child_count[0] == kEmptyChild)
            fail(node, slot, "empty child slot outside the root of a one-leaf tree");
        for (int a = 0; a < 3; ++a)
            if (!(n.lo(slot, a) > n.hi(slot, a)))
                fail(node, slot, "empty child slot has an enterable box (needs lo > hi on every axis)");
    }

    void check_leaf(uint32_t node, int slot, uint32_t first, uint32_t count) {
        if (count > kMaxLeafTriangles)
            fail(node, slot, "leaf of " + std::to_string(count) + " triangles (at most " +
                                 std::to_string(kMaxLeafTriangles) + ")");
        if (uint64_t(first) + count > m_tris.size())
            fail(node, slot, "leaf triangles [" + std::to_string(first) + ", " +
                                 std::to_string(uint64_t(first) + count) + ") out of range (" +
                                 std::to_string(m_tris.size()) + " triangles)");
        for (uint32_t t = first; t < first + count; ++t) {
            if (m_tri_seen[t])
                fail(node, slot, "triangle " + std::to_string(t) + " belongs to two leaves");
            m_tri_seen[t] = 1;
            const uint32_t prim = m_tris[t].prim;
            if (prim >= m_tris.size())
                fail(node, slot, "triangle " + std::to_string(t) + " has primitive id " +
                                     std::to_string(prim) + " (at most " + std::to_string(m_tris.size() - 1) + ")");
            if (m_prim_seen[prim])
                fail(node, slot, "triangle " + std::to_string(t) + " repeats primitive id " + std::to_string(prim));
            m_prim_seen[prim] = 1;
        }
    }

    const std::vector<HwNode>& m_nodes;
    const std::vector<HwTriangle>& m_tris;
    const std::string& m_source;
    std::vector<uint8_t> m_node_seen, m_tri_seen, m_prim_seen;
    std::vector<Item> m_stack;
};

}  // namespace

void validate_bvh_image(const std::vector<HwNode>& nodes, const std::vector<HwTriangle>& triangles,
                        const std::string& source) {
    ImageChecker(nodes, triangles, source).run();
}

}  // namespace rtsim
