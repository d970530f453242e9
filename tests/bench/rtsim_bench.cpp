// rtsim-bench: the reference tracer against Embree 3 on one scene, one thread each.
//   Structures: --accel KIND[:BUILDER],... (default bvh8,bvh2): each is built through the registry
//   (build_accel; BUILDER: the kind's builder, e.g. bvh8:sbvh) and traced with its Accel::trace
//   (the fused loops); the first is "rtsim" in the top-level figures, every one is under
//   "structures", named as given.
//   BVH build: rtsim's build of each structure and Embree's rtcCommitScene (high quality), one
//   thread; with --build-threads N > 1 also rtsim's build on N threads (wall time, its speed-up
//   over the one-thread build in the same run, and the CPU time of all threads).
//   Closest hit: primary rays (automatic framing camera) and one diffuse bounce from their hits.
//   Any hit: shadow rays from the primary hits to a point light in the upper middle of the scene
//   (Sponza has no lights; the light exists only for this benchmark).
// Runs are interleaved (rtsim, Embree, Embree, rtsim, ...) and each figure is the median of
// --repeat runs, in wall time and in the thread's CPU time. Not a test: nothing is asserted.
//
//   rtsim-bench [SCENE] [--json FILE] [--repeat N] [--resolution WxH] [--hairball-triangles N]
//               [--accel KIND[:BUILDER],...] [--build-threads N]
// The JSON also records the host (CPU model, hardware threads), its load average before and
// after the run, and the date: the figures of a shared machine mean little without them.
// SCENE: a glTF path or a built-in procedural scene name; default $RTSIM_SCENES/sponza/Sponza.gltf.
#include <cstdio>
#include <cstdlib>
#include <ctime>
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
    unsigned build_threads = 1;
};

/// "kind" or "kind:builder" as build options.
AccelOptions accel_options(const std::string& spec) {
    AccelOptions o;
    const size_t colon = spec.find(':');
    o.kind = spec.substr(0, colon);
    if (colon != std::string::npos) o.builder = spec.substr(colon + 1);
    return o;
}

[[noreturn]] void usage(const std::string& why) {
    std::fprintf(stderr,
                 "rtsim-bench: %s\nusage: rtsim-bench [SCENE] [--json FILE] [--repeat N] "
                 "[--resolution WxH] [--hairball-triangles N] [--accel KIND[:BUILDER],...] [--build-threads N]\n",
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
        } else if (arg == "--build-threads") a.build_threads = unsigned(parse_count(arg, value()));
        else if (arg == "--hairball-triangles") a.procedural.hairball_triangles = uint32_t(parse_count(arg, value()));
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
    for (const std::string& spec : a.accel) {
        AccelOptions o = accel_options(spec);
        try {
            validate_accel_options(o);
        } catch (const std::exception& e) {
            usage(std::string("--accel ") + spec + ": " + e.what());
        }
    }
    if (a.scene.empty()) {
        const char* env = std::getenv("RTSIM_SCENES");
        a.scene = (std::filesystem::path(env && *env ? env : RTSIM_SCENES_DIR) / "sponza" / "Sponza.gltf").string();
    }
    return a;
}

json sample_json(const Sample& s) { return {{"wall_ms", 1e3 * s.wall}, {"cpu_ms", 1e3 * s.cpu}}; }

double process_cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

/// Builds of every structure and of Embree, interleaved, `repeat` times each; with threads > 1
/// also each structure's build on that many threads (wall time; CPU time of the whole process).
json bench_build(const Scene& scene, const std::vector<std::string>& kinds, int repeat, unsigned threads) {
    std::vector<std::vector<Sample>> ours(kinds.size()), parallel(kinds.size());
    std::vector<Sample> theirs;
    for (int i = 0; i < repeat; ++i) {
        for (size_t k = 0; k < kinds.size(); ++k) {
            AccelOptions o = accel_options(kinds[k]);
            ours[k].push_back(time_once([&] { build_accel(scene, o); }));
            if (threads <= 1) continue;
            o.build_threads = threads;
            const double c0 = process_cpu_seconds();
            Sample s = time_once([&] { build_accel(scene, o); });
            s.cpu = process_cpu_seconds() - c0;
            parallel[k].push_back(s);
        }
        const oracle::EmbreeScene e(scene, oracle::EmbreeScene::Options{});
        theirs.push_back({e.commit_wall_seconds, e.commit_cpu_seconds});
    }
    json j = {{"rtsim", sample_json(median(ours[0]))}, {"embree", sample_json(median(theirs))}};
    for (size_t k = 0; k < kinds.size(); ++k) {
        j["structures"][kinds[k]] = sample_json(median(ours[k]));
        if (threads <= 1) continue;
        const Sample one = median(ours[k]), many = median(parallel[k]);
        j["parallel"]["threads"] = threads;
        j["parallel"]["structures"][kinds[k]] = {{"wall_ms", 1e3 * many.wall},
                                                 {"process_cpu_ms", 1e3 * many.cpu},
                                                 {"speedup_wall", one.wall / many.wall}};
    }
    return j;
}

/// The machine the figures come from: CPU model, hardware threads, and the 1-minute load average.
std::string cpu_model() {
    std::ifstream in("/proc/cpuinfo");
    for (std::string line; std::getline(in, line);)
        if (line.rfind("model name", 0) == 0 && line.find(':') != std::string::npos)
            return line.substr(line.find(':') + 2);
    return "unknown";
}

double load_average() {
    std::ifstream in("/proc/loadavg");
    double one = -1.0;
    in >> one;
    return one;
}

std::string utc_now() {
    const std::time_t now = std::time(nullptr);
    char text[32];
    std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
    return text;
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
    std::printf("\n%-14s %12s %12s %14s\n", "build", "wall ms", "cpu ms", "cpu / Embree");
    const double embree_cpu = j["build"]["embree"]["cpu_ms"].get<double>();
    for (const auto& [accel, b] : j["build"]["structures"].items())
        std::printf("%-14s %12.1f %12.1f %14.2f\n", accel.c_str(), b["wall_ms"].get<double>(), b["cpu_ms"].get<double>(),
                    b["cpu_ms"].get<double>() / embree_cpu);
    if (j["build"].contains("parallel")) {
        const json& p = j["build"]["parallel"];
        std::printf("\n%-14s %12s %16s %12s   (%u threads)\n", "build", "wall ms", "process cpu ms", "speed-up",
                    p["threads"].get<unsigned>());
        for (const auto& [accel, b] : p["structures"].items())
            std::printf("%-14s %12.1f %16.1f %12.2f\n", accel.c_str(), b["wall_ms"].get<double>(),
                        b["process_cpu_ms"].get<double>(), b["speedup_wall"].get<double>());
    }
    std::printf("\n%s, %s, load average %.2f -> %.2f\n", j["date"].get<std::string>().c_str(),
                j["host"]["cpu"].get<std::string>().c_str(), j["host"]["load_average_start"].get<double>(),
                j["host"]["load_average_end"].get<double>());
}

int run(const Args& args) {
    const std::string scratch = (std::filesystem::temp_directory_path() / "rtsim_bench").string();
    const Scene scene = oracle::load_named_scene(args.scene, scratch, args.procedural);
    if (scene.triangle_count() == 0) throw std::runtime_error(args.scene + ": the scene has no triangles");
    const HwBvh bvh = build_bvh(scene);
    const oracle::RaySets sets = oracle::make_ray_sets(scene, bvh, args.width, args.height);
    const oracle::EmbreeScene embree(scene, oracle::EmbreeScene::Options{});
    Accels accels;
    for (const std::string& kind : args.accel) accels.emplace_back(kind, load_accel(build_accel(scene, accel_options(kind)), kind));

    json j;
    j["date"] = utc_now();
    j["host"] = {{"cpu", cpu_model()}, {"load_average_start", load_average()}};
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
    j["build"] = bench_build(scene, args.accel, args.repeat, args.build_threads);
    j["rays"]["primary"] = bench_rays(accels, embree, sets.primary, false, args.repeat);
    j["rays"]["diffuse"] = bench_rays(accels, embree, sets.diffuse, false, args.repeat);
    j["rays"]["shadow"] = bench_rays(accels, embree, sets.shadow, true, args.repeat);
    j["host"]["load_average_end"] = load_average();
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
