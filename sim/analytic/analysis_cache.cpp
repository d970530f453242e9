#include "sim/analytic/analysis_cache.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <vector>

namespace rtsim {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

/// Bumped whenever the analysis or its meaning changes: old files are then simply not found.
constexpr int kAnalysisVersion = 15;  // 15: lock-step groups wait for their lines (rounds as time); 14: rounds as time (a step served below the L1 holds its context); 13: packets' oriented node steps; 12: phase windows under treelet scheduling; 11: windows' busy contexts; 10: the phases' machine; 9: frame samples; 8: packets' node steps by their operation kind; 7: phase windows, occupied lanes

struct Fnv {
    uint64_t h = 1469598103934665603ull;
    void add(const void* data, size_t n) {
        const auto* p = static_cast<const unsigned char*>(data);
        for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
    }
    template <class T>
    void add(const T& v) {
        add(&v, sizeof v);
    }
    std::string hex() const {
        char buf[17];
        std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
        return buf;
    }
};

}  // namespace

std::string trace_identity(const TraceReader& reader) {
    Fnv f;
    std::ifstream in(reader.path(), std::ios::binary);
    in.seekg(0, std::ios::end);
    const uint64_t size = uint64_t(in.tellg());
    f.add(size);
    f.add(reader.version());
    std::vector<char> crcs;
    for (const SectionInfo& s : reader.sections()) {
        f.add(uint32_t(s.kind));
        f.add(s.record_bytes);
        f.add(s.record_count);
        f.add(s.chunk_bytes);
        const uint64_t chunks = s.chunk_bytes ? (s.bytes + s.chunk_bytes - 1) / s.chunk_bytes : 0;
        crcs.resize(size_t(chunks) * 4);
        in.seekg(std::streamoff(s.crc_offset));
        in.read(crcs.data(), std::streamsize(crcs.size()));
        f.add(crcs.data(), crcs.size());
    }
    return f.hex();
}

json analysis_key(const SimConfig& c, const AnalyticConfig& s, const std::string& identity) {
    json key = {{"version", kAnalysisVersion},
            {"trace", identity},
            {"units", c.traversal.units},
            {"ray_contexts", c.traversal.contexts()},
            {"stack_entries", c.traversal.stack_entries},
            {"stack_entry_bytes", c.traversal.stack_entry_bytes},
            {"dispatch", {{"policy", kDispatchPolicyChoices.name(c.dispatch.policy)},
                          {"block_rays", c.dispatch.block_rays},
                          {"chunk_rays", c.dispatch.chunk_rays}}},
            {"line_bytes", c.l1.line_bytes},
            {"sample", {{"whole_trace_rays", s.whole_trace_rays},
                        {"clusters", s.clusters},
                        {"warmup_rays", s.resolved_warmup_rays(c.l2.lines())},
                        {"measured_rays", s.measured_rays}}}};
    // What the steppers walk with changes the stepped work (mailbox lookups, restarts, the
    // reduced-precision walk); named only when set, so a plain run's key is as it always was.
    if (c.mailbox.entries) key["mailbox_entries"] = c.mailbox.entries;
    if (c.traversal.stack_overflow != StackOverflow::spill) key["short_stack_entries"] = c.traversal.stack_entries;
    if (c.traversal.box_precision_bits) key["box_precision_bits"] = c.traversal.box_precision_bits;
    if (c.traversal.quantized_boxes) key["quantized_boxes"] = true;
    if (c.traversal.anyhit_order != AnyHitOrder::nearest)
        key["anyhit_order"] = kAnyHitOrderChoices.name(c.traversal.anyhit_order);
    // Treelet scheduling orders the sample's steps (sample.h): its settings, when on.
    if (c.treelets.enabled) {
        const json t = config_to_json(c)["treelets"];
        key["treelets"] = {{"treelet_kib", t["treelet_kib"]}, {"buffer_kib", t["buffer_kib"]},
                           {"policy", t["policy"]},         {"max_rays_in_flight", t["max_rays_in_flight"]},
                           {"stack_entries", c.traversal.stack_entries}};
    }
    // A lock-step kind's groups are profiled with its own settings (UnitKind::group_profile).
    if (c.traversal.kind().group_profile)
        key["unit"] = {{"model", c.traversal.model},
                       {"section", config_to_json(c)["traversal"][c.traversal.model]}};
    return key;
}

std::string analysis_path(const std::string& rtt, const json& key) {
    const char* env = std::getenv("RTSIM_ANALYTIC_CACHE");
    const std::string setting = env ? env : "";
    if (setting == "off" || setting == "0") return "";
    Fnv f;
    const std::string text = key.dump();
    f.add(text.data(), text.size());
    const fs::path dir = setting.empty() ? fs::path(rtt).parent_path() / "analytic" : fs::path(setting);
    return (dir / (f.hex() + ".json")).string();
}

std::optional<AnalyticProfile> load_analysis(const std::string& path, const json& key) {
    if (path.empty() || !fs::exists(path)) return std::nullopt;
    std::ifstream in(path);
    const json j = json::parse(in, nullptr, false);
    if (j.is_discarded() || !j.is_object() || j.value("key", json()) != key) return std::nullopt;
    try {
        return AnalyticProfile::from_json(j);
    } catch (const std::exception&) {
        return std::nullopt;  // a damaged file is recomputed, never trusted
    }
}

bool store_analysis(const std::string& path, const AnalyticProfile& profile) {
    if (path.empty()) return false;
    std::error_code ec;
    fs::create_directories(fs::path(path).parent_path(), ec);
    const std::string tmp = path + ".tmp" + std::to_string(::getpid());
    {
        std::ofstream out(tmp);
        if (!out) return false;
        out << profile.to_json().dump() << "\n";
        if (!out) return false;
    }
    fs::rename(tmp, path, ec);
    if (ec) fs::remove(tmp, ec);
    return !ec;
}

AnalysisLock::AnalysisLock(const std::string& path) {
    if (path.empty()) return;
    std::error_code ec;
    fs::create_directories(fs::path(path).parent_path(), ec);
    m_fd = ::open((path + ".lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (m_fd >= 0 && ::flock(m_fd, LOCK_EX) != 0) {
        ::close(m_fd);
        m_fd = -1;
    }
}

AnalysisLock::~AnalysisLock() {
    if (m_fd >= 0) {
        ::flock(m_fd, LOCK_UN);
        ::close(m_fd);
    }
}

}  // namespace rtsim
