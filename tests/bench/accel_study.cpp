// rtsim-accel-study: the build-side figures of acceleration structures on one scene, one thread
// (docs/accel.md, "Comparison"; scripts/accel_study.py adds the per-ray and model figures from
// traces). For each structure: build wall and CPU time (median of --repeat builds through the
// registry, as `rtsim trace` builds), footprint, nodes, node bytes, SAH cost; for the wide kinds
// also the SAH cost of the greedy collapse of the same binary tree (Wald et al. 2008) next to the
// SAH-optimal one the structure uses (Ylitie et al. 2017). Not a test: nothing is asserted.
//
// Structures are KIND or KIND:BUILDER (bvh2:sbvh), any registered one; the grid has no SAH cost.
//
//   rtsim-accel-study [SCENE] [--accel KIND[:BUILDER],...|all] [--repeat N] [--json FILE] [--hairball-triangles N]
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench_timing.h"
#include "oracle_rays.h"
#include "traces/accel/accel.h"
#include "traces/accel/wide/wide.h"
#include "traces/common/build_info.h"
#include "traces/bvh/build_tree.h"

namespace rtsim::bench {
namespace {

using nlohmann::json;

struct Args {
    std::string scene, json_path;
    std::vector<std::string> accel;
    int repeat = 3;
    ProceduralOptions procedural;
};

[[noreturn]] void usage(const std::string& why) {
    std::fprintf(stderr,
                 "rtsim-accel-study: %s\nusage: rtsim-accel-study [SCENE] [--accel KIND,...|all] [--repeat N] "
                 "[--json FILE] [--hairball-triangles N]\n",
                 why.c_str());
    std::exit(2);
}

Args parse_args(int argc, char** argv) {
    Args a;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= argc) usage(arg + " needs a value");
            return argv[++i];
        };
        if (arg == "--json") a.json_path = value();
        else if (arg == "--repeat") a.repeat = std::max(1, std::atoi(value().c_str()));
        else if (arg == "--hairball-triangles") a.procedural.hairball_triangles = uint32_t(std::atoi(value().c_str()));
        else if (arg == "--accel") {
            const std::string list = value() + ",";
            for (size_t at = 0, comma; (comma = list.find(',', at)) != std::string::npos; at = comma + 1)
                if (comma > at) a.accel.push_back(list.substr(at, comma - at));
        } else if (arg == "-h" || arg == "--help") usage("help");
        else if (!arg.empty() && arg[0] == '-') usage("unknown option " + arg);
        else if (a.scene.empty()) a.scene = arg;
        else usage("more than one scene given");
    }
    if (a.accel.empty() || (a.accel.size() == 1 && a.accel[0] == "all")) {
        a.accel.clear();
        for (const AccelKindInfo& k : accel_kinds()) a.accel.push_back(k.name);
    }
    if (a.scene.empty()) {
        const char* env = std::getenv("RTSIM_SCENES");
        a.scene = (std::filesystem::path(env && *env ? env : RTSIM_SCENES_DIR) / "sponza" / "Sponza.gltf").string();
    }
    return a;
}

/// SAH cost of the greedy collapse of the tree this structure collapses (wide kinds only).
double greedy_sah(const Scene& scene, const AccelImage& image) {
    const int width = image.stats["width"].get<int>();
    const BuildConfig config;
    const ChildOrder order = image.params.value("order", "distance") == "octant" ? ChildOrder::octant : ChildOrder::distance;
    const WideBuildTree greedy =
        make_wide_tree(build_binned_sah(scene.triangles, config), scene, width, config, order, Collapse::greedy);
    return wide_sah_cost(greedy, config.traversal_cost, config.intersection_cost);
}

/// Bytes of the image's structure: every region but the triangle records (nodes, or cells and
/// references).
uint64_t structure_bytes(const AccelImage& image) {
    uint64_t bytes = 0;
    for (const Region& r : image.regions)
        if (r.name != "triangles") bytes += r.size_bytes();
    return bytes;
}

json study(const Scene& scene, const std::string& entry, int repeat) {
    AccelOptions o;
    const size_t colon = entry.find(':');
    o.kind = entry.substr(0, colon);
    if (colon != std::string::npos) o.builder = entry.substr(colon + 1);
    std::vector<Sample> times;
    AccelImage image;
    for (int i = 0; i < repeat; ++i) times.push_back(time_once([&] { image = build_accel(scene, o); }));
    const Sample t = median(times);
    json j = image.stats;
    j["kind"] = o.kind;
    j["build_ms_wall"] = 1e3 * t.wall;
    j["build_ms_cpu"] = 1e3 * t.cpu;
    j["footprint_bytes"] = image.footprint_bytes();
    j["structure_bytes"] = structure_bytes(image);
    if (image.stats.value("collapse", "") == "dp") j["sah_cost_greedy"] = greedy_sah(scene, image);
    return j;
}

int run(const Args& args) {
    const std::string scratch = (std::filesystem::temp_directory_path() / "rtsim_accel_study").string();
    const Scene scene = oracle::load_named_scene(args.scene, scratch, args.procedural);
    json j = {{"scene", args.scene}, {"triangles", scene.triangle_count()}, {"repeat", args.repeat},
              {"git", rtsim_git_hash()}, {"structures", json::object()}};
    std::printf("%-14s %9s %9s %12s %9s %9s %10s\n", "structure", "build ms", "cpu ms", "footprint", "nodes", "SAH",
                "SAH greedy");
    for (const std::string& entry : args.accel) {
        const json s = study(scene, entry, args.repeat);
        j["structures"][entry] = s;
        std::printf("%-14s %9.1f %9.1f %12llu %9llu %9.2f %10s\n", entry.c_str(), s["build_ms_wall"].get<double>(),
                    s["build_ms_cpu"].get<double>(), (unsigned long long)s["footprint_bytes"].get<uint64_t>(),
                    (unsigned long long)s.value("nodes", uint64_t(0)), s.value("sah_cost", 0.0),
                    s.contains("sah_cost_greedy") ? std::to_string(s["sah_cost_greedy"].get<double>()).c_str() : "-");
    }
    if (!args.json_path.empty()) {
        std::ofstream out(args.json_path);
        out << j.dump(2) << "\n";
        if (!out) throw std::runtime_error("cannot write " + args.json_path);
    }
    return 0;
}

}  // namespace
}  // namespace rtsim::bench

int main(int argc, char** argv) {
    try {
        return rtsim::bench::run(rtsim::bench::parse_args(argc, argv));
    } catch (const std::exception& e) {
        std::fprintf(stderr, "rtsim-accel-study: error: %s\n", e.what());
        return 1;
    }
}
