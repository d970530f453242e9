#pragma once
// A short traversal stack with a restart trail (docs/accel.md, "Short stacks"), kept beside a
// stepper's full stack so hits and the reference work never change.
//
// Hardware keeps only `entries` stack entries per ray. A push onto a full short stack drops its
// oldest entry; a pop that finds the short stack empty while entries were dropped restarts the
// traversal at the root, and the restart trail (Laine 2010, "Restart Trail for Stackless BVH
// Traversal", HPG) says at each level which children are already done, so the re-descent
// follows the path to the next unvisited node, pushes the pending siblings it passes (the short
// stack refills with the newest of them), and then continues in exactly the order a full stack
// would. Vaidyanathan, Woop & Benthin 2019 ("Wide BVH Traversal with a Short Stack", HPG) apply
// it to wide BVHs and report a 5-entry stack close to a full one.
//
// Because the trail reproduces the full stack's order, the stepper keeps walking with its full
// stack (the definition of hits and reference work) and this shadow says when the hardware
// would restart and which nodes its re-descent revisits: the ancestors of the entry being
// resumed (root first), known because a depth-first walk's current path still holds them. Each
// revisit is a planned step of its own (node fetch and box tests), counted in the model-only
// work fields restarts, restart_steps and restart_box_tests and in stack_drops, never in the
// reference fields. One approximation, said in docs/accel.md: when the entries resumed after a
// restart are all culled by a closer hit, the re-descent is charged the root only.
#include <algorithm>
#include <cstdint>

namespace rtsim {

/// Deepest path a short-stack shadow remembers (BVH builders cap depth well below it; a deeper
/// node's re-descent is charged the first kMaxShortStackPath levels).
constexpr uint32_t kMaxShortStackPath = 128;

class ShortStack {
public:
    /// entries: on-chip entries per ray; 0 turns the shadow off (a full stack, the default).
    void configure(uint32_t entries) { m_entries = entries; }
    bool enabled() const { return m_entries != 0; }

    void begin() { m_on_chip = 0, m_replay_next = m_replay_end = 0; }
    /// The walk visits `node` at `depth` (root 0).
    void visit(uint32_t node, uint32_t depth) {
        if (depth < kMaxShortStackPath) m_path[depth] = node;
    }
    /// One entry pushed: returns true when the short stack was full and dropped its oldest.
    bool push() {
        if (m_on_chip < m_entries) return ++m_on_chip, false;
        return true;
    }
    /// One entry popped (taken or culled): returns true when it had been dropped (the hardware
    /// finds its short stack empty and must restart).
    bool pop() {
        if (m_on_chip > 0) return --m_on_chip, false;
        return true;
    }
    /// A restart that resumes at an entry of `depth` with `remaining` entries still below it on
    /// the full stack: its re-descent revisits the path's first `depth` nodes (at least the
    /// root), and the short stack refills with the newest of the pending entries it passes.
    /// `first` > 0 starts the re-descent at the path's node of that depth instead of the root
    /// (kd-restart's push-down, cell_stepper.h).
    void restart(uint32_t depth, uint32_t remaining, uint32_t first = 0) {
        m_replay_end = std::min(std::max(depth, 1u), kMaxShortStackPath);
        m_replay_next = std::min(first, m_replay_end - 1);
        m_on_chip = std::min(m_entries, remaining);
    }
    /// True while the re-descent has nodes left to revisit.
    bool replaying() const { return m_replay_next < m_replay_end; }
    /// The next node the re-descent revisits (replaying() must be true).
    uint32_t replay_node() const { return m_path[m_replay_next]; }
    void replay_advance() { ++m_replay_next; }

private:
    uint32_t m_entries = 0;
    uint32_t m_on_chip = 0;
    uint32_t m_replay_next = 0, m_replay_end = 0;
    uint32_t m_path[kMaxShortStackPath];
};

}  // namespace rtsim
