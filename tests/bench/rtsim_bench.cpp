// rtsim-bench: the reference tracer against Embree 3 on one scene, one thread each.
//   Structures: --accel KIND,... (default bvh8,bvh2): each is built through the registry
//   (build_accel) and traced with its Accel::trace (the fused loops); the first is "rtsim" in the
//   top-level figures, every one is under "structures".
//   BVH build: rtsim's build of each structure and Embree's rtcCommitScene (high quality).
//   Closest hit: primary rays (automatic framing camera) and one diffuse bounce from their hits.
//   Any hit: shadow rays from the primary hits to a point light in the upper middle of the scene
//   (Sponza has no lights; the light exists only for this benchmark).
// Runs are interleaved (rtsim, Embree, Embree, rtsim, ...) and each figure is the median of
// --repeat runs, in wall time and in the thread's CPU time. Not a test: nothing is asserted.
//
//   rtsim-bench [SCENE] [--json FILE] [--repeat N] [--resolution WxH] [--hairball-triangles N]
//               [--accel KIND,...]
// SCENE: a glTF path or a built-in procedural scene name; default $RTSIM_SCENES/sponza/Sponza.gltf.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench_timing.h"
#include "embree_oracle.h"
#include "oracle_rays.h"
#include "traces/accel/accel.h"
#include "traces/bvh/builder.h"
#include "traces/common/build_info.h"

namespace rtsim::bench {
namespace {

using nlohmann::json;

struct Args {
    std::string scene;
    std::string json_path;
    int repeat = 5;
    uint32_t width = 640, height = 480;
    ProceduralOptions procedural;
    std::vector<std::string> accel = {"bvh8", "bvh2"};
};

[[noreturn]] void usage(const std::string& why) {
    std::fprintf(stderr,
                 "rtsim-bench: %s\nusage: rtsim-bench [SCENE] [--json FILE] [--repeat N] "
                 "[--resolution WxH] [--hairball-triangles N] [--accel KIND,...]\n",
                 why.c_str());
    std::exit(2);
}

uint64_t parse_count(const std::string& flag, const std::string& text) {
    char* end = nullptr;
    const unsigned long long v = std::strtoull(text.c_str(), &end, 10);
    if (text.empty() || *end != '\0' || v == 0) usage(flag + " expects a positive integer, got '" + text + "'");
    return v;
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
        else if (arg == "--repeat") a.repeat = int(parse_count(arg, value()));
        else if (arg == "--accel") {
            a.accel.clear();
            std::string list = value() + ",";
            for (size_t at = 0, comma; (comma = list.find(',', at)) != std::string::npos; at = comma + 1)
                if (comma > at) a.accel.push_back(list.substr(at, comma - at));
            if (a.accel.empty()) usage("--accel expects a comma-separated list of structures");
        } else if (arg == "--hairball-triangles") a.procedural.hairball_triangles = uint32_t(parse_count(arg, value()));
        else if (arg == "--resolution") {
            const std::string v = value();
            const size_t x = v.find('x');
            if (x == std::string::npos) usage("--resolution expects WxH, got '" + v + "'");
            a.width = uint32_t(parse_count(arg, v.substr(0, x)));
            a.height = uint32_t(parse_count(arg, v.substr(x + 1)));
        } else if (arg == "-h" || arg == "--help") usage("help");
        else if (!arg.empty() && arg[0] == '-') usage("unknown option " + arg);
        else if (a.scene.empty()) a.scene = arg;
        else usage("more than one scene given");
    }
    if (a.scene.empty()) {
        const char* env = std::getenv("RTSIM_SCENES");
        a.scene = (std::filesystem::path(env && *env ? env : RTSIM_SCENES_DIR) / "sponza" / "Sponza.gltf").string();
    }
    return a;
}

json sample_json(const Sample& s) { return {{"wall_ms", 1e3 * s.wall}, {"cpu_ms", 1e3 * s.cpu}}; }

/// Builds of every structure and of Embree, interleaved, `repeat` times each.
json bench_build(const Scene& scene, const std::vector<std::string>& kinds, int repeat) {
    std::vector<std::vector<Sample>> ours(kinds.size());
    std::vector<Sample> theirs;
    for (int i = 0; i < repeat; ++i) {
        for (size_t k = 0; k < kinds.size(); ++k) {
            AccelOptions o;
            o.kind = kinds[k];
            ours[k].push_back(time_once([&] { build_accel(scene, o); }));
        }
        const oracle::EmbreeScene e(scene, oracle::EmbreeScene::Options{});
        theirs.push_back({e.commit_wall_seconds, e.commit_cpu_seconds});
    }
    json j = {{"rtsim", sample_json(median(ours[0]))}, {"embree", sample_json(median(theirs))}};
    for (size_t k = 0; k < kinds.size(); ++k) j["structures"][kinds[k]] = sample_json(median(ours[k]));
    return j;
}

json throughput_json(const Sample& s, size_t rays, uint64_t hits) {
    return {{"wall_ms", 1e3 * s.wall}, {"cpu_ms", 1e3 * s.cpu}, {"mrays_per_s_wall", 1e-6 * double(rays) / s.wall},
            {"mrays_per_s_cpu", 1e-6 * double(rays) / s.cpu}, {"hits", hits}};
}

using Accels = std::vector<std::pair<std::string, std::unique_ptr<Accel>>>;

/// One ray set through every structure and Embree, interleaved (the order alternates per run).
json bench_rays(const Accels& accels, const oracle::EmbreeScene& embree, const std::vector<Ray>& rays, bool any,
                int repeat) {
    const TraversalMode mode = any ? TraversalMode::any_hit : TraversalMode::closest_hit;
    std::vector<uint64_t> ours_hits(accels.size(), 0);
    uint64_t theirs_hits = 0;
    auto run_one = [&](size_t k) {
        uint64_t h = 0;
        const Accel& a = *accels[k].second;
        for (const Ray& r : rays) h += a.trace(r, mode).valid();
        ours_hits[k] = h;
    };
    auto run_theirs = [&] {
        uint64_t h = 0;
        if (any)
            for (const Ray& r : rays) h += embree.occluded(r);
        else
            for (const Ray& r : rays) h += embree.intersect(r).valid();
        theirs_hits = h;
    };
    std::vector<std::vector<Sample>> ours(accels.size());
    std::vector<Sample> theirs;
    for (int i = 0; i < repeat; ++i) {
        if (i % 2 == 1) theirs.push_back(time_once(run_theirs));
        for (size_t n = 0; n < accels.size(); ++n) {
            const size_t k = i % 2 == 0 ? n : accels.size() - 1 - n;  // alternate the order too
            ours[k].push_back(time_once([&] { run_one(k); }));
        }
        if (i % 2 == 0) theirs.push_back(time_once(run_theirs));
    }
    const Sample b = median(theirs);
    json j = {{"mode", any ? "any_hit" : "closest_hit"},
              {"rays", rays.size()},
              {"embree", throughput_json(b, rays.size(), theirs_hits)}};
    for (size_t k = 0; k < accels.size(); ++k) {
        const Sample a = median(ours[k]);
        json f = {{"rtsim", throughput_json(a, rays.size(), ours_hits[k])},
                  {"ratio_cpu", b.cpu / a.cpu},
                  {"ratio_wall", b.wall / a.wall}};
        if (k == 0) j.update(f);
        j["structures"][accels[k].first] = f;
    }
    return j;
}

void print_report(const json& j) {
    std::printf("rtsim-bench: %s (%llu triangles), %ux%u, median of %d interleaved runs, one thread each\n",
                j["scene"].get<std::string>().c_str(), (unsigned long long)j["triangles"].get<uint64_t>(),
                j["resolution"][0].get<unsigned>(), j["resolution"][1].get<unsigned>(), j["repeat"].get<int>());
    std::printf("rtsim %s (git %s), Embree %s (robust, high quality, threads=1); %u hardware threads\n",
                j["rtsim_version"].get<std::string>().c_str(), j["git"].get<std::string>().c_str(),
                j["embree_version"].get<std::string>().c_str(), j["hardware_threads"].get<unsigned>());
    std::printf("shadow light: %s\n\n", j["light_note"].get<std::string>().c_str());
    const json& b = j["build"];
    std::printf("%-10s %12s %12s %14s %14s\n", "BVH build", "rtsim ms", "rtsim cpu ms", "Embree ms", "Embree cpu ms");
    std::printf("%-10s %12.1f %12.1f %14.1f %14.1f\n\n", j["accel"][0].get<std::string>().c_str(),
                b["rtsim"]["wall_ms"].get<double>(),
                b["rtsim"]["cpu_ms"].get<double>(), b["embree"]["wall_ms"].get<double>(),
                b["embree"]["cpu_ms"].get<double>());
    std::printf("%-8s %-11s %8s %21s %21s %16s\n", "rays", "mode", "count", "rtsim Mrays/s cpu|wall",
                "Embree Mrays/s cpu|wall", "rtsim/Embree cpu");
    for (const char* kind : {"primary", "diffuse", "shadow"}) {
        const json& r = j["rays"][kind];
        for (const auto& [accel, f] : r["structures"].items())
            std::printf("%-8s %-11s %8llu %11.2f|%-9.2f %11.2f|%-9.2f %16.3f  %s\n", kind,
                        r["mode"].get<std::string>().c_str(), (unsigned long long)r["rays"].get<uint64_t>(),
                        f["rtsim"]["mrays_per_s_cpu"].get<double>(), f["rtsim"]["mrays_per_s_wall"].get<double>(),
                        r["embree"]["mrays_per_s_cpu"].get<double>(), r["embree"]["mrays_per_s_wall"].get<double>(),
                        f["ratio_cpu"].get<double>(), accel.c_str());
    }
    std::printf("\n%-10s %12s %12s\n", "build", "wall ms", "cpu ms");
    for (const auto& [accel, b] : j["build"]["structures"].items())
        std::printf("%-10s %12.1f %12.1f\n", accel.c_str(), b["wall_ms"].get<double>(), b["cpu_ms"].get<double>());
}

int run(const Args& args) {
    const std::string scratch = (std::filesystem::temp_directory_path() / "rtsim_bench").string();
    const Scene scene = oracle::load_named_scene(args.scene, scratch, args.procedural);
    if (scene.triangle_count() == 0) throw std::runtime_error(args.scene + ": the scene has no triangles");
    const HwBvh bvh = build_bvh(scene);
    const oracle::RaySets sets = oracle::make_ray_sets(scene, bvh, args.width, args.height);
    const oracle::EmbreeScene embree(scene, oracle::EmbreeScene::Options{});
    Accels accels;
    for (const std::string& kind : args.accel) {
        AccelOptions o;
        o.kind = kind;
        accels.emplace_back(kind, load_accel(build_accel(scene, o), kind));
    }

    json j;
    j["scene"] = args.scene;
    j["triangles"] = scene.triangle_count();
    j["resolution"] = {args.width, args.height};
    j["repeat"] = args.repeat;
    j["rtsim_version"] = rtsim_version();
    j["git"] = rtsim_git_hash();
    j["embree_version"] = RTC_VERSION_STRING;
    j["hardware_threads"] = std::thread::hardware_concurrency();
    j["camera"] = sets.camera_why;
    j["light"] = {sets.light.x, sets.light.y, sets.light.z};
    j["light_note"] = scene.lights.empty()
                          ? "point light placed by the benchmark (the scene has no lights) at the scene's "
                            "horizontal centre, 80% up"
                          : "point light placed by the benchmark at the scene's horizontal centre, 80% up "
                            "(the scene's own lights are not used)";
    j["accel"] = args.accel;
    j["build"] = bench_build(scene, args.accel, args.repeat);
    j["rays"]["primary"] = bench_rays(accels, embree, sets.primary, false, args.repeat);
    j["rays"]["diffuse"] = bench_rays(accels, embree, sets.diffuse, false, args.repeat);
    j["rays"]["shadow"] = bench_rays(accels, embree, sets.shadow, true, args.repeat);
    // Throughput ratio rtsim / Embree = Embree time / rtsim time.
    print_report(j);
    if (!args.json_path.empty()) {
        std::ofstream out(args.json_path);
        out << j.dump(2) << "\n";
        if (!out) throw std::runtime_error("cannot write " + args.json_path);
        std::printf("\nwrote %s\n", args.json_path.c_str());
    }
    return 0;
}

}  // namespace
}  // namespace rtsim::bench

int main(int argc, char** argv) {
    try {
        return rtsim::bench::run(rtsim::bench::parse_args(argc, argv));
    } catch (const std::exception& e) {
        std::fprintf(stderr, "rtsim-bench: error: %s\n", e.what());
        return 1;
    }
}
