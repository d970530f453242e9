#include "sim/harness/run_inputs.h"


#include <filesystem>
#include <iostream>

#include "sim/analytic/analysis_cache.h"
#include "sim/harness/alternative_trace.h"
#include "sim/harness/frames.h"
#include "sim/harness/memory_estimate.h"
#include "sim/harness/run_files.h"
#include "sim/harness/trace_stream.h"
#include "sim/report/technique_cost.h"
#include "traces/accel/accel_io.h"
#include "traces/common/error.h"

namespace rtsim {

namespace fs = std::filesystem;
using nlohmann::json;

RunInputs::RunInputs(const SimOptions& o)
    : options(o),
      t0(std::chrono::steady_clock::now()),
      started(std::time(nullptr)),
      rtt(trace_file(o.trace)),
      reader(rtt),
      manifest(read_manifest(rtt)),
      setup(resolve_run(o.config, structure_facts(reader))) {
    fs::create_directories(o.out_dir);
    write_json(fs::path(o.out_dir) / "config.resolved.json", config_to_json(setup.config));
    // The config as given, before it was resolved against this trace's structure: what another
    // structure's trace is simulated with (the verdict's measure commands, --check-verdict).
    write_json(fs::path(o.out_dir) / "config.given.json", config_to_json(o.config));
}

double RunInputs::wall_seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

BuiltRun build_run(RunInputs& in, bool per_ray_spills) {
    const SimConfig& c = in.config();
    BuiltRun b;
    // The acceleration structure, whichever it is, validated structurally (load_accel).
    b.accel = load_accel(read_accel_image(in.reader), in.rtt);
    // Animated traces (frames.h): replayed frame after frame, caches warm, one barrier between.
    b.frames = read_frame_table(in.reader, b.accel->frame_count());
    check_sim_memory(c, b.accel->image().footprint_bytes(),
                     "config (fidelity=" + std::string(kFidelityChoices.name(c.fidelity)) +
                         ", traversal.units=" + std::to_string(c.traversal.units) +
                         ", traversal.ray_contexts=" + std::to_string(c.traversal.contexts()) + ")");
    b.workload = scan_workload(in.reader, &b.features);
    // Check every chunk's CRC now (one streaming pass): the reference window reads HITS and WORK
    // during sc_start, where a corrupt chunk would surface as a SystemC report (exit 1) instead
    // of an error naming the file (exit 2).
    in.reader.verify_all();
    b.rays = b.workload["rays"];
    const TraversalConfig& t = c.traversal;
    // The model's own regions start past the image; a trace's textures lie far above them
    // (from 1 TiB, traces/shading/materials.h), checked by the shading block's inputs.
    b.map = std::make_unique<MemoryMap>(b.accel->image().end_address(), b.rays,
                                        per_ray_spills ? b.rays : uint64_t(t.units) * t.contexts(),
                                        b.accel->max_stack_entries(), t.stack_entry_bytes);
    return b;
}

std::function<void(uint64_t done, uint64_t total)> progress_of(const SimOptions& options) {
    if (!options.progress) return {};
    return [](uint64_t done, uint64_t total) {
        std::cerr << "{\"progress\": " << done << ", \"total\": " << total << "}" << std::endl;
    };
}

StructureTraits structure_traits(const RunInputs& in) {
    const StructureFacts& f = in.setup.structure;
    StructureTraits t;
    t.kind = f.kind;
    t.blas_kind = f.blas_kind;
    t.compressed_leaves = f.compressed_leaves;
    // Compressed leaves index triangle vertices: a scene with spheres or capsules refuses them.
    const json scene = in.manifest.value("scene", json::object());
    const bool curved = scene.is_object() && (scene.value("spheres", 0) > 0 || scene.value("capsules", 0) > 0);
    t.curved = curved;
    t.treelet_partition = f.caps.treelet_partition;
    t.stack_addresses = f.caps.stack_addresses;
    t.quantized_boxes = f.caps.quantized_boxes;
    t.trace = in.rtt;
    t.run = in.options.out_dir;
    const json frames = in.manifest.value("frames", json(nullptr));
    if (frames.is_object() && frames.contains("policy") && frames["policy"].is_string())
        t.frame_policy = frames["policy"].get<std::string>();
    return t;
}

json with_structure_blocks(json instantiated, const StructureFacts& s) {
    for (json& b : structure_blocks(s.kind, s.blas_kind, s.compressed_leaves)) instantiated.push_back(std::move(b));
    return instantiated;
}

UnitTraits unit_traits(const RunSetup& setup) {
    UnitTraits u;
    u.name = setup.unit->name;
    for (const UnitKnob& k : setup.unit->knobs) u.knobs.push_back({k.key, k.halve, k.resource, k.estimated});
    // The verdict estimates with the analytic level, which costs a lock-step kind's groups only
    // from its functional group profile: without one, the stand-in kind's estimate.
    if (setup.unit->needs.lock_step && !setup.unit->group_profile) u.estimate_as = setup.unit->estimate_as;
    return u;
}

VerdictContext verdict_context(RunInputs& in, const BuiltRun& built, const json& model, const json& instantiated) {
    VerdictContext v{in.config(), model, built.accel.get(), built.map.get()};
    TraceReader& reader = in.reader;
    v.sample_stream = [&reader](uint64_t first, uint64_t rays, uint64_t sample) -> std::unique_ptr<RayStream> {
        return std::make_unique<SampleStream>(reader, first, rays, sample);
    };
    v.step = in.setup.step;
    v.identity = trace_identity(in.reader);
    v.trace_rays = built.rays;
    v.unit = unit_traits(in.setup);
    v.trace_path = in.rtt;
    v.instantiated = with_structure_blocks(instantiated, in.setup.structure);
    v.structure = structure_traits(in);
    v.frames = built.frames.size();
    if (built.frames.size() == 1) {
        v.alternative = alternative_traces(in.rtt, in.options.config, built.rays);
    } else {
        // The estimates trace a sample of rays against one bound structure: an animated trace's
        // first frame, its rays against its structure.
        built.accel->bind_frame(0);
        v.first_ray = built.frames[0].first_ray;
        v.frame_rays = built.frames[0].rays;
    }
    return v;
}

}  // namespace rtsim
