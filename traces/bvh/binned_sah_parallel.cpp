// The binned SAH build on several threads (build_binned_sah with threads > 1), giving the tree
// of the single-threaded build node for node: the same splits, the same reference order, the
// same node numbering.
//
// The top of the tree is split on the calling thread until nodes hold fewer than a grain of
// references; each smaller node is a task whose whole subtree one thread builds into its own
// node array (subtrees own disjoint ranges of the references, so the threads share nothing
// else). Tasks are handed out largest first. Finally the node arrays are stitched together in
// the order the single-threaded build allocates nodes: a depth-first walk, left child first,
// that gives each split node's children the next pair of indices.
#include <algorithm>
#include <atomic>
#include <exception>
#include <numeric>
#include <thread>

#include "traces/bvh/binned_sah_impl.h"

namespace rtsim {
namespace binned_detail {
namespace {

/// Tasks per thread: enough that handing out the largest first balances the threads.
constexpr uint32_t kTasksPerThread = 8;
/// No task is made smaller than this: below it a thread's hand-off costs more than it saves.
constexpr uint32_t kMinTask = 4096;

/// A node of the stitched tree: array 0 is the top's nodes, array t + 1 task t's.
struct Handle {
    uint32_t array, index;
};

/// The nodes of `top` and of the tasks' arrays in the single-threaded build's numbering.
BuildNodes stitch(const BuildNodes& top, const std::vector<BuildNodes>& local,
                              const std::vector<uint32_t>& task_of, size_t total, uint32_t max_depth) {
    auto at = [&](Handle h) -> const BuildNode& { return h.array == 0 ? top[h.index] : local[h.array - 1][h.index]; };
    // A top node that was handed to a task is that task's root.
    auto resolve = [&](Handle h) { return h.array == 0 && task_of[h.index] ? Handle{task_of[h.index], 0} : h; };
    BuildNodes out(total);
    std::vector<std::pair<Handle, uint32_t>> stack;  // a node and its index in `out`
    stack.reserve(2 * size_t(max_depth) + 2);
    stack.push_back({resolve({0, 0}), 0});
    out[0] = at(stack.back().first);
    uint32_t next = 1;
    while (!stack.empty()) {
        const auto [h, to] = stack.back();
        stack.pop_back();
        const BuildNode& b = at(h);
        if (b.is_leaf()) continue;
        const Handle left = resolve({h.array, b.first}), right = resolve({h.array, b.first + 1});
        out[to].first = next;
        out[next] = at(left);
        out[next + 1] = at(right);
        stack.push_back({right, next + 1});
        stack.push_back({left, next});
        next += 2;
    }
    return out;
}

}  // namespace

void build_parallel(PrimRefs& refs, const BuildConfig& config, const WorkItem& root, unsigned threads,
                    BuildNodes& nodes) {
    const uint32_t grain = std::max(kMinTask, (root.end - root.begin) / (kTasksPerThread * threads));
    // The top of the tree, here; nodes of at most `grain` references become tasks.
    std::vector<WorkItem> stack{root}, tasks;
    NodeSplitter top(refs.data(), config);
    while (!stack.empty()) {
        const WorkItem item = stack.back();
        stack.pop_back();
        if (item.end - item.begin <= grain) tasks.push_back(item);
        else top.split_node(item, nodes, stack);
    }

    // Each task's subtree into its own array (its root first), largest tasks first.
    std::vector<uint32_t> order(tasks.size());
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
        return tasks[a].end - tasks[a].begin > tasks[b].end - tasks[b].begin;
    });
    std::vector<BuildNodes> local(tasks.size());
    std::atomic<size_t> next{0};
    std::exception_ptr error;
    std::atomic<bool> failed{false};
    auto worker = [&] {
        try {
            NodeSplitter splitter(refs.data(), config);
            for (size_t k; !failed && (k = next.fetch_add(1)) < order.size();) {
                const WorkItem& task = tasks[order[k]];
                BuildNodes& out = local[order[k]];
                out.reserve(2 * size_t(task.end - task.begin));
                out.push_back(nodes[task.node]);
                WorkItem subtree = task;
                subtree.node = 0;
                splitter.build_subtree(subtree, out);
            }
        } catch (...) {
            if (!failed.exchange(true)) error = std::current_exception();
        }
    };
    std::vector<std::thread> pool;
    for (unsigned t = 1; t < std::min<size_t>(threads, tasks.size()); ++t) pool.emplace_back(worker);
    worker();
    for (std::thread& t : pool) t.join();
    if (error) std::rethrow_exception(error);

    std::vector<uint32_t> task_of(nodes.size(), 0);
    size_t total = nodes.size();
    for (size_t t = 0; t < tasks.size(); ++t) {
        task_of[tasks[t].node] = uint32_t(t + 1);
        total += local[t].size() - 1;
    }
    nodes = stitch(nodes, local, task_of, total, config.max_depth);
}

}  // namespace binned_detail
}  // namespace rtsim
