#include "sim/harness/run_files.h"

#include <fstream>
#include <iterator>
#include <vector>

#include "traces/common/error.h"

namespace rtsim {

namespace fs = std::filesystem;
using nlohmann::json;

std::string trace_file(const std::string& path) {
    fs::path p(path);
    if (fs::is_directory(p)) p /= "trace.rtt";
    require(fs::exists(p), path + ": no trace here (expected a trace folder or a .rtt file)");
    return p.string();
}

json read_manifest(const std::string& rtt) {
    fs::path m = fs::path(rtt).parent_path() / "manifest.json";
    std::error_code ec;
    if (!fs::exists(m, ec)) return json::object();
    require(fs::is_regular_file(m, ec), m.string() + ": is not a file (expected the trace's manifest)");
    std::ifstream in(m);
    require(bool(in), m.string() + ": cannot open");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    json j = json::parse(text, nullptr, false);
    require(!j.is_discarded(), m.string() + ": not valid JSON");
    require(j.is_object(), m.string() + ": expected a JSON object (the trace manifest), found " + j.type_name());
    // The keys the harness reads (provenance, effects) must have their documented types.
    auto check = [&](const json& parent, const char* key, bool (json::*is)() const noexcept, const char* what,
                     const std::string& path) {
        const auto it = parent.find(key);
        require(it == parent.end() || ((*it).*is)(), m.string() + ": '" + path + "' must be " + what);
    };
    check(j, "workload", &json::is_object, "an object", "workload");
    check(j, "scene", &json::is_object, "an object", "scene");
    check(j, "git", &json::is_string, "a string", "git");
    if (j.contains("scene")) check(j["scene"], "name", &json::is_string, "a string", "scene.name");
    // An animated trace's per-frame figures, read at each frame's end (frames.h).
    check(j, "frames", &json::is_object, "an object", "frames");
    if (j.contains("frames")) {
        check(j["frames"], "per_frame", &json::is_array, "an array", "frames.per_frame");
        const json& per = j["frames"].value("per_frame", json::array());
        for (size_t f = 0; f < per.size(); ++f) {
            const std::string at = "frames.per_frame[" + std::to_string(f) + "]";
            require(per[f].is_object(), m.string() + ": '" + at + "' must be an object");
            for (const char* key : {"tlas_build_ms", "tlas_nodes"})
                require(!per[f].contains(key) || per[f][key].is_number() || per[f][key].is_null(),
                        m.string() + ": '" + at + "." + key + "' must be a number");
        }
    }
    return j;
}

json scan_workload(TraceReader& reader, WorkloadFeatures* features) {
    WorkloadFeatures ignored;
    if (!features) features = &ignored;
    const uint64_t n = reader.section(SectionKind::rays).record_count;
    std::vector<RayRecord> buf(65536);
    uint64_t kinds[kRayKindCount] = {};
    for (uint64_t first = 0; first < n; first += buf.size()) {
        uint64_t count = std::min<uint64_t>(buf.size(), n - first);
        reader.read(SectionKind::rays, first, count, buf.data());
        for (uint64_t i = 0; i < count; ++i) {
            if (buf[i].kind >= kRayKindCount)  // the message is built only on failure: a loop over every ray
                throw Error(reader.path() + ": ray " + std::to_string(first + i) + " has unknown ray kind " +
                            std::to_string(buf[i].kind) + " (known kinds: 0.." + std::to_string(kRayKindCount - 1) +
                            ")");
            ++kinds[buf[i].kind];
            features->occlusion_rays += (buf[i].flags & kRayFlagAnyHit) != 0;
        }
    }
    json by_kind = json::object();
    for (int k = 0; k < kRayKindCount; ++k)
        if (kinds[k]) by_kind[ray_kind_name(RayKind(k))] = kinds[k];
    return {{"rays", n}, {"by_kind", by_kind}, {"occlusion_rays", features->occlusion_rays}};
}

void write_json(const fs::path& path, const json& j) {
    std::ofstream out(path);
    require(bool(out), path.string() + ": cannot write");
    out << j.dump(2) << "\n";
}

const StatBlock& workload_stats() {
    static const StatBlock block{
        "workload",
        {
            {"rays", "rays", "rays in the trace"},
            {"by_kind", "rays", "`{kind: rays}` for each ray kind present (`primary`, `shadow`, `reflection`, `diffuse`, `refraction`)"},
            {"occlusion_rays", "rays", "rays with the any-hit flag (shadow rays): they stop at their first hit"},
        }};
    return block;
}

RTSIM_REGISTER_STAT_BLOCK(workload_stats)

}  // namespace rtsim
