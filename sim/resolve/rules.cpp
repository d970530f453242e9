#include "sim/resolve/rules.h"

#include "rtl_model/traversal/packet/packet_config.h"

namespace rtsim {

namespace {

bool restart_trail(const RunFacts& f) { return f.config.traversal.stack_overflow == StackOverflow::restart_trail; }
bool reduced_boxes(const RunFacts& f) { return f.config.traversal.box_precision_bits != 0; }
bool quantized_boxes(const RunFacts& f) { return f.config.traversal.quantized_boxes; }
bool anyhit_reordered(const RunFacts& f) { return f.config.traversal.anyhit_order != AnyHitOrder::nearest; }
/// The run's any-hit order differs from the one its trace was traced in.
bool anyhit_off_trace(const RunFacts& f) { return f.config.traversal.anyhit_order != f.structure.traced_anyhit_order; }
bool treelets(const RunFacts& f) { return f.config.treelets.enabled; }
bool sampling(const RunFacts& f) { return f.config.sampling.enabled(); }
bool animated(const RunFacts& f) { return f.structure.frames > 1; }
bool shading(const RunFacts& f) { return f.config.shading.enabled; }

/// How a message names the side a rule matches against.
std::string side_name(const Rule& r, const RunFacts& f) {
    switch (r.side) {
        case RuleSide::structure: return f.structure.name();
        case RuleSide::unit: return "traversal.model '" + f.unit.name + "'";
        case RuleSide::level: return "fidelity '" + f.level.name + "'";
        case RuleSide::technique: break;
    }
    return "this run";
}

std::vector<Rule> make_rules() {
    std::vector<Rule> rules;
    auto add = [&](Rule r) { rules.push_back(std::move(r)); };

    // Unit kinds: what their groups need.
    add({"unit/packet_kernel", "traversal.model (a kind whose rays step as one packet)",
         [](const RunFacts& f) { return f.unit.needs.packet_kernel; }, RuleSide::structure, "a packet kernel",
         [](const RunFacts& f) { return f.structure.caps.packet_kernel; },
         "a packet's rays walk one shared traversal, which the structure provides as a packet stepper and a "
         "reference packet loop (the hit checker checks each packet's work against it); every registered "
         "structure has one (the BVHs, the oriented BVH, kd-tree, BIH, B-Kd tree, octree, grid and two levels "
         "over them), so only a structure registered without one meets this",
         "traversal.model=mimd or simt, or trace a structure with a packet kernel (rtsim capabilities)", "",
         {"traversal.model=packet"}});
    add({"unit/groups", "traversal.ray_contexts",
         [](const RunFacts& f) { return f.config.traversal.ray_contexts != 0 && f.unit.group_size(f.config.traversal) > 1; },
         RuleSide::unit, "a whole number of its groups (warps or packets)",
         [](const RunFacts& f) {
             return f.config.traversal.ray_contexts % f.unit.group_size(f.config.traversal) == 0;
         },
         "a unit's ray contexts are its warps' lanes or its packets' rays",
         "traversal.ray_contexts a multiple of the kind's lanes, or 0 (derived: 16 rounded up to whole groups)",
         "bvh2", {"traversal.model=simt", "traversal.ray_contexts=20"}});
    add({"unit/lock_step", "traversal.model (a kind whose rays step in lock-step groups)",
         [](const RunFacts& f) { return f.unit.needs.lock_step; }, RuleSide::level, "a level that costs lock-step groups",
         [](const RunFacts& f) {
             return f.level.lock_step || (f.level.group_profiles && f.unit.group_profile != nullptr);
         },
         "the analytic level's functional caches cost each ray context on its own (its statistical caches cost "
         "warps and packets from the kind's functional group profile)",
         "analytic.caches=statistical, fidelity=approx or detailed, or traversal.model=mimd", "bvh2",
         {"traversal.model=simt", "fidelity=analytic", "analytic.caches=functional"}});

    // Treelet scheduling.
    add({"treelets/unit", "treelets.enabled=true", treelets, RuleSide::unit,
         "a unit kind whose rays can leave for other treelets' queues one by one",
         [](const RunFacts& f) { return f.unit.needs.treelet_queues; },
         "a packet's rays share one walk, while a treelet queue holds single rays", "traversal.model=mimd or simt, or "
         "treelets.enabled=false",
         "bvh2", {"traversal.model=packet", "treelets.enabled=true"}});
    add({"treelets/level", "treelets.enabled=true", treelets, RuleSide::level, "a level that models treelet queues",
         [](const RunFacts& f) { return f.level.treelets; },
         "the analytic level's functional caches step rays in plain dispatch order (its statistical caches step "
         "the sample in treelet order)",
         "analytic.caches=statistical, or fidelity=approx or detailed", "bvh2",
         {"treelets.enabled=true", "fidelity=analytic", "analytic.caches=functional"}});
    add({"sort/treelets", "dispatch.sort (ray sorting)", [](const RunFacts& f) { return f.config.dispatch.sort != RaySort::none; },
         RuleSide::technique, "treelets.enabled=false", [](const RunFacts& f) { return !treelets(f); },
         "the ray buffer takes rays from dispatch in its own order and reorders them by treelet itself",
         "dispatch.sort=none, or treelets.enabled=false", "bvh2", {"dispatch.sort=morton", "treelets.enabled=true"}});

    // Per-ray traversal techniques.
    add({"restart_trail/structure", "traversal.stack_overflow=restart_trail", restart_trail, RuleSide::structure,
         "a restart trail", [](const RunFacts& f) { return f.structure.caps.restart_trail; },
         "a restart re-descends a tree to the entries its short stack dropped (Laine 2010's trail on BVHs and the "
         "BIH, kd-restart with push-down on kd-trees, Foley & Sugerman 2005): a grid's 3D-DDA keeps no stack to "
         "shorten, and the octree's eight-child parametric walk has no trail built",
         "traversal.stack_overflow=spill, or trace a structure with a restart trail (rtsim capabilities)", "grid",
         {"traversal.stack_overflow=restart_trail"}});
    add({"restart_trail/unit", "traversal.stack_overflow=restart_trail", restart_trail, RuleSide::unit,
         "a unit kind whose rays walk their own stacks", [](const RunFacts& f) { return f.unit.needs.per_ray_stack; },
         "a packet's rays share one stack, and the restart trail is a single ray's",
         "traversal.model=mimd or simt, or traversal.stack_overflow=spill", "bvh2",
         {"traversal.model=packet", "traversal.stack_overflow=restart_trail"}});
    add({"box_precision/structure", "traversal.box_precision_bits (reduced-precision boxes)", reduced_boxes,
         RuleSide::structure, "a reduced-precision box walk",
         [](const RunFacts& f) { return f.structure.caps.reduced_precision_boxes; },
         "the conservative walk re-tests a BVH's child boxes rounded outward (Vaidyanathan et al. 2016) and "
         "counts the extra subtrees it enters; a space partition's cells are cut by planes, not bounded by "
         "boxes, so it has no box to narrow",
         "traversal.box_precision_bits=0 (fp32), or trace a structure with a reduced-precision walk (rtsim "
         "capabilities)",
         "grid", {"traversal.box_precision_bits=7"}});
    add({"box_precision/unit", "traversal.box_precision_bits (reduced-precision boxes)", reduced_boxes, RuleSide::unit,
         "a unit kind whose rays walk their own stacks", [](const RunFacts& f) { return f.unit.needs.per_ray_stack; },
         "a packet's shared walk has no per-ray extra walk", "traversal.model=mimd or simt, or box_precision_bits=0",
         "bvh2", {"traversal.model=packet", "traversal.box_precision_bits=7"}});

    add({"quantized_boxes/structure", "traversal.quantized_boxes (AQB8-style integer box pipeline)", quantized_boxes,
         RuleSide::structure, "quantised nodes", [](const RunFacts& f) { return f.structure.caps.quantized_boxes; },
         "an integer box pipeline tests child boxes stored as 8-bit integers on their node's grid, which only "
         "the compressed wide BVHs store",
         "traversal.quantized_boxes=false, or trace cwbvh6 or cwbvh8 (rtsim capabilities)", "bvh2",
         {"traversal.quantized_boxes=true"}});
    add({"quantized_boxes/unit", "traversal.quantized_boxes (AQB8-style integer box pipeline)", quantized_boxes,
         RuleSide::unit, "a unit kind whose rays walk their own stacks",
         [](const RunFacts& f) { return f.unit.needs.per_ray_stack; }, "a packet's shared walk has no per-ray extra walk",
         "traversal.model=mimd or simt, or traversal.quantized_boxes=false", "cwbvh8",
         {"traversal.model=packet", "traversal.quantized_boxes=true"}});
    add({"quantized_boxes/precision", "traversal.quantized_boxes (AQB8-style integer box pipeline)", quantized_boxes,
         RuleSide::technique, "traversal.box_precision_bits=0",
         [](const RunFacts& f) { return f.config.traversal.box_precision_bits == 0; },
         "the box pipeline is either integer on quantised boxes or a reduced-precision floating-point one",
         "traversal.box_precision_bits=0 or traversal.quantized_boxes=false", "cwbvh8",
         {"traversal.quantized_boxes=true", "traversal.box_precision_bits=7"}});

    add({"anyhit_order/structure", "traversal.anyhit_order (any-hit child order)", anyhit_reordered,
         RuleSide::structure, "an any-hit child order", [](const RunFacts& f) { return f.structure.caps.anyhit_order; },
         "the order is chosen among a BVH node's child boxes (binary, wide and compressed BVHs); the kd-tree, "
         "BIH, B-Kd tree, octree and grid visit near cells before far ones by their own rules",
         "traversal.anyhit_order=nearest, or trace a structure with the setting (rtsim capabilities)", "grid",
         {"traversal.anyhit_order=fixed"}});
    add({"anyhit_order/level", "traversal.anyhit_order (any-hit child order)", anyhit_off_trace, RuleSide::level,
         "a level that steps every ray (functional, approx, detailed, or analytic with analytic.caches=functional)",
         [](const RunFacts& f) {
             return f.config.fidelity == Fidelity::functional || f.level.timed ||
                    (f.config.fidelity == Fidelity::analytic && f.config.analytic.caches == AnalyticCaches::functional);
         },
         "the analytic level's statistical caches take the work of the rays they do not step from the trace, "
         "traced in another order (nearest first unless rtsim trace --anyhit-order), and another order finds "
         "other occluders with other work; the levels that step every ray check a reordered any-hit ray's "
         "occlusion against the trace and count and time its own walk",
         "fidelity=functional, approx or detailed, analytic.caches=functional, traversal.anyhit_order set to "
         "the trace's, or a trace traced in the run's order (rtsim trace --anyhit-order)",
         "bvh2", {"traversal.anyhit_order=fixed", "fidelity=analytic"}});

    // Sampling.
    add({"sampling/level", "sampling.fraction or sampling.count", sampling, RuleSide::level, "a timed level",
         [](const RunFacts& f) { return f.level.timed; },
         "a sample's clusters are timed on the SystemC model and scaled to the whole trace",
         "fidelity=approx or detailed", "bvh2", {"sampling.fraction=0.2", "fidelity=functional"}});
    add({"sampling/size", "sampling.fraction", [](const RunFacts& f) { return f.config.sampling.fraction > 0; },
         RuleSide::technique, "sampling.count 0", [](const RunFacts& f) { return f.config.sampling.count == 0; },
         "a sample is sized one way", "set sampling.fraction or sampling.count, not both", "bvh2",
         {"sampling.fraction=0.2", "sampling.count=100"}});

    // Animated traces (docs/accel.md, "Frames").
    add({"frames/level", "an animated trace (--frames)", animated, RuleSide::level, "a level that replays frames",
         [](const RunFacts& f) { return f.level.frames; },
         "the analytic level's functional caches step every ray in one pass over one structure, not frame by frame",
         "analytic.caches=statistical, or fidelity=functional, approx or detailed", "frames",
         {"fidelity=analytic", "analytic.caches=functional"}});

    // The frame: shading and the frame loop (docs/shading.md).
    add({"shading/level", "shading.enabled (the frame: shading and the frame loop)", shading, RuleSide::level,
         "a level that times the frame", [](const RunFacts& f) { return f.level.shades; },
         "shader cores, texture caches and the frame loop are SystemC blocks", "fidelity=approx or detailed",
         "bvh2", {"shading.enabled=true", "fidelity=analytic"}});
    add({"shading/sampling", "shading.enabled (the frame: shading and the frame loop)", shading,
         RuleSide::technique, "no sampling (sampling.fraction and sampling.count 0)",
         [](const RunFacts& f) { return !sampling(f); },
         "a frame's rays depend on their parents' shading, which a sample of rays leaves out",
         "sampling.fraction=0", "bvh2", {"shading.enabled=true", "sampling.fraction=0.2"}});
    add({"shading/treelets", "shading.enabled (the frame: shading and the frame loop)", shading,
         RuleSide::technique, "treelets.enabled=false", [](const RunFacts& f) { return !treelets(f); },
         "the treelet ray buffer takes rays ahead of the frame loop's barriers and parent order",
         "treelets.enabled=false", "bvh2", {"shading.enabled=true", "treelets.enabled=true"}});
    return rules;
}

}  // namespace

const std::vector<Rule>& run_rules() {
    static const std::vector<Rule> rules = make_rules();
    return rules;
}

std::string refusal(const Rule& r, const RunFacts& f) {
    const std::string asks = r.asks.rfind("an ", 0) == 0 ? r.asks : "'" + r.asks + "'";
    std::string side = side_name(r, f);
    if (r.side == RuleSide::technique) return "config: " + asks + " needs " + r.needs + ": " + r.reason + "; change " + r.change;
    return "config: " + asks + " needs " + r.needs + ", which " + side + " lacks: " + r.reason + "; change " + r.change;
}

std::vector<Unused> unused_settings(const RunFacts& f) {
    std::vector<Unused> out;
    // A unit kind's own section set away from its defaults while another kind runs.
    const nlohmann::json mine = config_to_json(f.config)["traversal"];
    static const nlohmann::json defaults = config_to_json(SimConfig{})["traversal"];  // once per process
    for (const UnitKind* k : unit_kinds()) {
        if (k->name == f.config.traversal.model || !mine.contains(k->name) || !mine[k->name].is_object()) continue;
        for (auto it = mine[k->name].begin(); it != mine[k->name].end(); ++it)
            if (defaults[k->name].value(it.key(), nlohmann::json()) != it.value())
                out.push_back({"traversal." + k->name + "." + it.key(),
                               "a setting of the " + k->name + " unit kind; traversal.model is " + f.config.traversal.model});
    }
    if (f.config.mailbox.entries && !f.structure.caps.mailbox)
        out.push_back({"mailbox.entries", f.structure.name() + " lists no primitive twice along a ray"});
    if (f.config.treelets.prefetch && f.config.ideal_memory)
        out.push_back({"treelets.prefetch", "with ideal_memory every access hits: there is nothing to prefetch"});
    else if (f.config.treelets.prefetch && !f.unit.needs.treelet_prefetch)
        out.push_back({"treelets.prefetch", "the " + f.unit.name + " unit's rays share one walk, which does not trigger treelet prefetches"});
    else if (f.config.treelets.prefetch && !f.level.timed)
        out.push_back({"treelets.prefetch", "the untimed levels model no prefetches (the analytic level's caches see demand reads only)"});
    if (f.unit.needs.packet_kernel && f.structure.kind == "two_level" &&
        f.config.traversal.kinds.of<PacketConfig>("packet").split_walks == SplitWalks::lanes)
        out.push_back({"traversal.packet.split_walks", "a two-level packet splits inside instances, its rays finishing "
                                                       "the instance one after another on the packet's context (serial)"});
    if (f.config.traversal.stack_prefetch && f.config.ideal_memory)
        out.push_back({"traversal.stack_prefetch", "with ideal_memory every access hits: there is nothing to prefetch"});
    else if (f.config.traversal.stack_prefetch && !f.structure.caps.stack_addresses)
        out.push_back({"traversal.stack_prefetch", f.structure.name() + "'s steppers report no stack addresses to prefetch"});
    else if (f.config.traversal.stack_prefetch && !f.level.timed)
        out.push_back({"traversal.stack_prefetch", "the untimed levels model no prefetches (the analytic level's caches see demand reads only)"});
    if (f.config.shading.enabled && !f.structure.shading_sections)
        out.push_back({"shading.enabled", "this trace has no shading sections (written before trace version 5): "
                                          "the RT unit alone is timed"});
    if (!f.config.shading.enabled && f.config.shading.reorder != ShadeReorder::none)
        out.push_back({"shading.reorder", "shading.enabled is false: no hit is shaded, so none is reordered"});
    return out;
}

}  // namespace rtsim
