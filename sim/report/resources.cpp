#include "sim/report/resources.h"

#include <algorithm>

namespace rtsim {

const std::vector<ResourceInfo>& resource_table() {
    static const std::vector<ResourceInfo> r = {
        {"l1_mshrs", "L1 MSHRs", "l1_mshrs"},
        {"l2_mshrs", "L2 MSHRs", "l2_mshrs"},
        {"dram", "DRAM bandwidth", "dram_bandwidth"},
        {"l1_banks", "L1 banks", "l1_banks"},
        {"l2_banks", "L2 banks", "l2_banks"},
        {"latency", "latency not hidden (memory and pipeline latency over too few ray contexts)", ""},
        {"scheduler", "the traversal units' schedulers (one step per issue_cycles)", ""},
        {"stack", "stack spills (spilled entries read back)", ""},
        {"ray_buffer", "the ray buffer SRAM", ""},
        {"workload", "the workload: too few rays to keep the machine busy (contexts idle)", ""},
        {"units", "too few traversal units (their per-unit contexts, schedulers, L1 MSHRs and pipelines)", ""},
        {"l1_capacity", "L1 capacity (misses to the L2)", ""},
        {"l2_capacity", "L2 capacity (misses to DRAM)", ""},
        {"admission", "treelet admission (rays admitted into the ray buffer)", ""},
        {"treelet_scheduling", "treelet scheduling (which queue a free unit runs)", ""},
        {"divergence", "divergence (SIMT warp lanes, or packet rays, masked off while others step)", ""},
        {"structure", "the acceleration structure (its work and bytes per ray)", ""},
        {"execution_model", "the execution model (how a unit runs its rays)", ""},
        {"ray_order", "ray order (sorting before dispatch)", ""},
        {"prefetch", "treelet prefetching (lines requested ahead of the rays)", ""},
        {"build", "the build unit (each frame's structures built or refit while its rays wait)", ""},
    };
    return r;
}

namespace {

const ResourceInfo* find_resource(const std::string& name) {
    for (const ResourceInfo& r : resource_table())
        if (name == r.name) return &r;
    return nullptr;
}

}  // namespace

bool resource_op_kind(const std::string& resource, OpKind* kind) {
    for (int k = 0; k < kOpKindCount; ++k)
        if (resource == op_kind_name(OpKind(k))) return *kind = OpKind(k), true;
    return false;
}

std::string resource_label(const std::string& resource) {
    OpKind kind;
    if (resource_op_kind(resource, &kind)) return resource + " pipelines";
    const ResourceInfo* r = find_resource(resource);
    return r ? r->label : resource;
}

std::string resource_busy(const std::string& resource) {
    OpKind kind;
    if (resource_op_kind(resource, &kind)) return std::string("pipe_") + op_kind_name(kind);
    const ResourceInfo* r = find_resource(resource);
    return r ? r->busy : "";
}

bool resource_per_unit(const SimConfig& c, const std::string& resource) {
    OpKind kind;
    if (resource_op_kind(resource, &kind)) return !c.pipeline(kind).shared();
    return resource == "latency" || resource == "scheduler" || resource == "l1_mshrs" || resource == "l1_banks" ||
           resource == "units";
}

std::vector<std::string> knob_relaxes(const SimConfig& c, const std::string& key) {
    std::vector<std::string> out;
    if (key == "traversal.units") {
        out = {"units", "latency", "scheduler", "l1_mshrs", "l1_banks"};
        for (int k = 0; k < kOpKindCount; ++k)
            if (!c.pipeline(OpKind(k)).shared()) out.push_back(op_kind_name(OpKind(k)));
    } else if (key == "traversal.ray_contexts" || key == "traversal.simt.warps") {
        out = {"latency", "workload"};
    } else if (key == "traversal.issue_cycles") {
        out = {"scheduler"};
    } else if (key == "l1.size_kib") {
        out = {"l1_capacity", "l1_mshrs", "l2_banks", "l2_mshrs", "dram"};
    } else if (key == "l2.size_kib") {
        out = {"l2_capacity", "l2_mshrs", "dram"};
    } else if (key == "l1.banks") {
        out = {"l1_banks"};
    } else if (key == "l2.banks") {
        out = {"l2_banks"};
    } else if (key == "l1.mshrs") {
        out = {"l1_mshrs"};
    } else if (key == "l2.mshrs") {
        out = {"l2_mshrs"};
    } else if (key == "dram.channels") {
        out = {"dram", "l2_mshrs"};
    } else if (key == "traversal.stack_entries") {
        out = {"stack"};
    } else if (key.rfind("build_unit.", 0) == 0 || key == "frame_policy") {
        out = {"build"};
    } else if (key == "accel" || key == "compressed_leaves") {
        // Another structure changes every demand a ray makes: its steps, its tests and the
        // bytes (and lines) each step reads.
        out = {"latency", "l1_capacity", "l1_mshrs", "l1_banks", "l2_capacity", "l2_mshrs", "l2_banks", "dram"};
        for (int k = 0; k < kOpKindCount; ++k) out.push_back(op_kind_name(OpKind(k)));
    } else if (key == "traversal.model") {
        out = {"divergence", "latency", "scheduler"};
    } else if (key.rfind("treelets.", 0) == 0) {
        out = {"admission", "ray_buffer", "treelet_scheduling"};
    } else {
        // A pipeline's knob (box.width, triangle.initiation_interval, ...) relaxes its kind.
        const std::string head = key.substr(0, key.find('.'));
        OpKind kind;
        if (resource_op_kind(head, &kind)) out = {head};
    }
    return out;
}

}  // namespace rtsim
