// The binned SAH build on several threads (build_binned_sah with threads > 1), giving the tree
// of the single-threaded build node for node: the same splits, the same reference order, the
// same node numbering.
//
// Every node is a task, split by whichever thread takes it; its children are tasks again. A
// node of more than a grain of references is split alone (its two children into a small array
// of its own, each handed on as a new task); a smaller node's whole subtree is built by one
// thread into its own node array. So the threads share the top of the tree as well as the
// subtrees: after the root, the two halves of the tree are split at the same time. Nodes own
// disjoint ranges of the references, so the threads share nothing else; a node's split depends
// only on its range, so the order in which the threads take the tasks changes no split. Tasks
// are taken largest first. Finally the arrays are stitched together in the order the
// single-threaded build allocates nodes: a depth-first walk, left child first, that gives each
// split node's children the next pair of indices.
#include <algorithm>
#include <array>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <queue>
#include <thread>

#include "traces/bvh/binned_sah_impl.h"

namespace rtsim {
namespace binned_detail {
namespace {

/// Subtree tasks per thread: enough that taking the largest first balances the threads.
constexpr uint32_t kTasksPerThread = 8;
/// No subtree task is made smaller than this: below it a hand-off costs more than it saves.
constexpr uint32_t kMinTask = 4096;

/// A node of the tree under construction: index `index` of array `array`.
struct Handle {
    uint32_t array, index;
};

/// The node arrays: one per task. A split task's array holds its node and its two children,
/// which were handed on (`handed[a]`: the arrays of those children's tasks); a subtree task's
/// array holds its whole subtree. Node 0 of every array is its task's root.
struct Arrays {
    std::deque<BuildNodes> nodes;                ///< a deque: arrays stay in place while others are added
    std::deque<std::array<uint32_t, 2>> handed;  ///< {0, 0}: nothing handed on

    const BuildNode& at(Handle h) const { return nodes[h.array][h.index]; }
    /// A handed-on child is its task's root.
    Handle resolve(Handle h) const {
        if (h.index == 0 || h.index > 2) return h;  // only nodes 1 and 2 are ever handed on
        const uint32_t to = handed[h.array][h.index - 1];
        return to ? Handle{to, 0} : h;
    }
};

/// The nodes in the single-threaded build's numbering, array 0 the root's.
BuildNodes stitch(const Arrays& arrays, size_t total, uint32_t max_depth) {
    BuildNodes out(total);
    std::vector<std::pair<Handle, uint32_t>> stack;  // a node and its index in `out`
    stack.reserve(2 * size_t(max_depth) + 2);
    stack.push_back({Handle{0, 0}, 0});
    out[0] = arrays.at(stack.back().first);
    uint32_t next = 1;
    while (!stack.empty()) {
        const auto [h, to] = stack.back();
        stack.pop_back();
        const BuildNode& b = arrays.at(h);
        if (b.is_leaf()) continue;
        const Handle left = arrays.resolve({h.array, b.first}),
                     right = arrays.resolve({h.array, b.first + 1});
        out[to].first = next;
        out[next] = arrays.at(left);
        out[next + 1] = arrays.at(right);
        stack.push_back({right, next + 1});
        stack.push_back({left, next});
        next += 2;
    }
    return out;
}

/// A node to split: its range, and the array its task fills (its root, node 0, already there).
struct Task {
    WorkItem item;
    uint32_t array;
    uint32_t size() const { return item.end - item.begin; }
    bool operator<(const Task& o) const { return size() < o.size(); }  // the largest on top
};

/// The tasks and their arrays, shared by the threads.
class TaskPool {
public:
    TaskPool(PrimRef* refs, const BuildConfig& config, uint32_t grain)
        : m_refs(refs), m_config(config), m_grain(grain) {}

    /// The root's task, before the threads start.
    void add_root(const WorkItem& root, const BuildNode& node) {
        std::lock_guard<std::mutex> lock(m_mutex);
        m_todo.push(new_task(root, node));
    }
    /// Takes tasks until every node is split; any thread's error ends every thread's work.
    void work() {
        try {
            NodeSplitter splitter(m_refs, m_config);
            Task t;
            for (BuildNodes* out; (out = take(t));) run(splitter, t, *out);
        } catch (...) {
            std::lock_guard<std::mutex> lock(m_mutex);
            if (!m_error) m_error = std::current_exception();
            m_stop = true;
            m_wake.notify_all();
        }
    }
    /// After every thread's work: the tree, or the first error.
    BuildNodes result() {
        if (m_error) std::rethrow_exception(m_error);
        size_t total = 1;  // the root, then each array's nodes but the root it shares with its parent
        for (const BuildNodes& a : m_arrays.nodes) total += a.size() - 1;
        return stitch(m_arrays, total, m_config.max_depth);
    }

private:
    /// A task's array holds its root; call with the lock held.
    Task new_task(const WorkItem& item, const BuildNode& node) {
        const uint32_t array = uint32_t(m_arrays.nodes.size());
        BuildNodes& nodes = m_arrays.nodes.emplace_back();
        m_arrays.handed.push_back({0, 0});
        const uint32_t size = item.end - item.begin;
        nodes.reserve(size > m_grain ? 3 : 2 * size_t(size));
        nodes.push_back(node);
        WorkItem local = item;
        local.node = 0;
        ++m_pending;
        return Task{local, array};
    }
    /// The next task and its array (found under the lock: another thread may be adding arrays),
    /// or null when every node is split or a thread failed.
    BuildNodes* take(Task& t) {
        std::unique_lock<std::mutex> lock(m_mutex);
        m_wake.wait(lock, [&] { return m_stop || !m_todo.empty() || m_pending == 0; });
        if (m_stop || m_todo.empty()) return nullptr;
        t = m_todo.top();
        m_todo.pop();
        return &m_arrays.nodes[t.array];
    }
    void run(NodeSplitter& splitter, const Task& t, BuildNodes& out) {
        if (t.size() <= m_grain) {
            splitter.build_subtree(t.item, out);
            finish({});
            return;
        }
        std::vector<WorkItem> children;
        splitter.split_node(t.item, out, children);
        finish(children, t.array, &out);
    }
    /// Hands on a split task's children (none for a leaf or a subtree) and retires the task.
    void finish(const std::vector<WorkItem>& children, uint32_t array = 0, const BuildNodes* out = nullptr) {
        std::lock_guard<std::mutex> lock(m_mutex);
        for (const WorkItem& c : children) {
            const Task child = new_task(c, (*out)[c.node]);
            m_arrays.handed[array][c.node - 1] = child.array;
            m_todo.push(child);
        }
        --m_pending;
        m_wake.notify_all();
    }

    PrimRef* const m_refs;
    const BuildConfig& m_config;
    const uint32_t m_grain;
    std::mutex m_mutex;
    std::condition_variable m_wake;
    std::priority_queue<Task> m_todo;
    Arrays m_arrays;
    size_t m_pending = 0;  ///< tasks queued or running
    bool m_stop = false;
    std::exception_ptr m_error;
};

}  // namespace

void build_parallel(PrimRefs& refs, const BuildConfig& config, const WorkItem& root, unsigned threads,
                    BuildNodes& nodes) {
    const uint32_t grain = std::max(kMinTask, (root.end - root.begin) / (kTasksPerThread * threads));
    TaskPool pool(refs.data(), config, grain);
    pool.add_root(root, nodes[root.node]);
    std::vector<std::thread> helpers;
    for (unsigned t = 1; t < threads; ++t) helpers.emplace_back([&pool] { pool.work(); });
    pool.work();
    for (std::thread& t : helpers) t.join();
    nodes = pool.result();
}

}  // namespace binned_detail
}  // namespace rtsim
