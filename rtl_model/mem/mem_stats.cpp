#include "rtl_model/mem/mem_stats.h"

#include <initializer_list>
#include <vector>

namespace rtsim {

namespace {
nlohmann::json counters_json(const MemCounters& c) {
    double hit_rate = c.reads ? double(c.read_hits + c.merged) / double(c.reads) : 0.0;
    return {{"reads", c.reads},           {"writes", c.writes},           {"read_hits", c.read_hits},
            {"merged", c.merged},         {"hit_rate", hit_rate},         {"read_bytes", c.read_bytes},
            {"write_bytes", c.write_bytes}};
}
/// The counters of a memory level (MemStats::to_json), without or with the hit fields.
std::vector<StatDecl> counter_stats(bool hits) {
    std::vector<StatDecl> d = {
        {"reads", "accesses", "read **line** accesses: a request spanning two lines counts twice"},
        {"writes", "accesses", "write line accesses (write-through, no-write-allocate: every write goes down)"},
        {"read_bytes", "bytes", "bytes requested by reads at this level"},
        {"write_bytes", "bytes", "bytes requested by writes (a 20-byte hit record counts 20)"},
        {"by_kind", "", "`{kind: counters}`: the same counters per data kind (only kinds that were accessed; absent when none was)", false, true},
    };
    if (hits) {
        d.push_back({"read_hits", "accesses", "reads that found the line present and filled"});
        d.push_back({"merged", "accesses", "reads that found the line allocated but still being filled (hit under miss)"});
        d.push_back({"hit_rate", "fraction", "`(read_hits + merged) / reads`: merged misses count as hits"});
    }
    return d;
}

std::vector<StatDecl> with(std::vector<StatDecl> a, std::initializer_list<StatDecl> b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

}  // namespace

const StatBlock& cache_stats() {
    static const StatBlock block{
        "model.l1.<l1>, model.l2",
        with(counter_stats(true),
             {
                 {"evictions", "lines", "valid lines replaced (LRU); `null` at the statistical analytic level (not estimated)"},
                 {"mshr_stall_cycles", "cycles", "total cycles misses waited for a free MSHR (the L2 at `approx`: waits of its occupancy bound, docs/model.md); `null` at analytic", true},
                 {"mshr_busy_cycles", "MSHR-cycles", "sum over misses of the cycles each held an MSHR; timed levels only", false, true},
                 {"mshr_occupancy", "MSHRs", "`mshr_busy_cycles / summary.cycles`: mean MSHRs in use; timed levels only", false, true},
                 {"mshr_utilization", "fraction", "`mshr_occupancy / config.mshrs`; timed levels only", false, true},
                 {"bank_utilization", "fraction", "bank accesses x `bank_cycles` / (`banks` x `summary.cycles`); timed levels only", false, true},
                 {"mshr_utilization_over_time", "list", "the L2's `[{cycle, value}]` per bucket, at most 256 points (the L1s' are merged in `model.utilization`)", false, true},
                 {"bank_utilization_over_time", "list", "the L2's bank utilisation the same way", false, true},
                 {"prefetch", "", "treelet prefetching (`treelets.prefetch`; written only where a prefetch reached this level): `issued` lines this level fetched for prefetches it is the target of; `redundant` prefetches of lines already present; `blocked` prefetches that found no free MSHR and were retried later; `useful` prefetched lines a read then used (`late`: of those, read while still being filled); `useless` evicted before any read; `resident` still unused at the end (`issued = useful + useless + resident`, tested); `below_bytes` bytes this level read from the level below for prefetches (at the L2: the DRAM traffic prefetching caused)", false, true},
                 {"config", "", "`size_kib`, `ways`, `line_bytes`, `latency`, `banks`: the cache's configuration; `mshrs`: MSHRs modelled (exact free-list in the L1s and, at `detailed`, the L2; an occupancy bound in the L2 at `approx`; `null` at analytic)"},
             })};
    return block;
}

const StatBlock& dram_stats() {
    static const StatBlock block{
        "model.dram",
        with(counter_stats(false),
             {
                 {"bandwidth_gbps", "GB/s", "`(read_bytes + write_bytes) / summary.seconds / 1e9`: the average over the run"},
                 {"peak_bandwidth_gbps", "GB/s", "`channels * bytes_per_cycle * clock_ghz`"},
                 {"bandwidth_utilization", "fraction", "`bandwidth_gbps / peak_bandwidth_gbps`"},
                 {"avg_queue_cycles", "cycles", "mean cycles a request waited for its channel's bandwidth, or with the bank model for its bank; `null` at analytic", true},
                 {"bandwidth_over_time", "list", "`[{cycle, gbps}]`: bytes per 1024-cycle bucket, merged to at most 256 points; `cycle` is the bucket's first cycle, `gbps` its average (empty at analytic)"},
                 {"row_hits", "requests", "bank model: the row was open in the bank's row buffer (column command at once)", false, true},
                 {"row_misses", "requests", "bank model: the bank was closed: activate, then column (`t_rcd`); every access with close page", false, true},
                 {"row_conflicts", "requests", "bank model: another row was open: precharge, activate, column (`t_rp + t_rcd`)", false, true},
                 {"row_hit_rate", "fraction", "bank model: `row_hits / (row_hits + row_misses + row_conflicts)`", false, true},
                 {"page_policy", "", "bank model: `open` or `close` (`dram.page_policy`)", false, true},
                 {"banks_per_channel", "banks", "bank model: banks per channel", false, true},
                 {"row_bytes", "bytes", "bank model: bytes per row", false, true},
                 {"ras_wait_cycles", "cycles", "bank model: cycles precharges waited for `t_ras` after their row's activate, summed (0 with `t_ras` 0)", false, true},
                 {"activate_wait_cycles", "cycles", "bank model: cycles activates waited for `t_rrd`, `t_rrd_l` and `t_faw`, summed (0 with all 0)", false, true},
                 {"refresh_wait_cycles", "cycles", "bank model: cycles accesses waited for a refresh (`t_refi`, `t_rfc`), summed", false, true},
                 {"column_wait_cycles", "cycles", "bank model: cycles column commands waited for `t_ccd_l` (one bank group) and the turnarounds `t_wtr`, `t_rtw`, summed (0 with all 0)", false, true},
                 {"queue_wait_cycles", "cycles", "bank model: cycles requests waited for an entry of their channel's full controller queue (`queue_entries`), summed (0 with no limit)", false, true},
                 {"queue_full_requests", "requests", "bank model: requests that found their channel's controller queue full", false, true},
                 {"scheduler", "", "bank model: the controller's order, `fcfs` or `frfcfs` (`dram.scheduler`)", false, true},
                 {"row_hits_first", "requests", "bank model, frfcfs: row hits served ahead of a booked access that changes the row", false, true},
                 {"moved_back_cycles", "cycles", "bank model, frfcfs: cycles the accesses they passed moved back, summed (those kept the times already returned: the reordering's optimism)", false, true},
                 {"bank_groups", "groups", "bank model: bank groups per channel (`dram.bank_groups`)", false, true},
                 {"group_interleave_bytes", "bytes", "bank model: the bank-group interleaving granule (`dram.group_interleave_bytes`; 0: off)", false, true},
                 {"by_bank", "list", "bank model: `[{channel, bank, accesses, row_hits, row_misses, row_conflicts}]` for every bank accessed", false, true},
             })};
    return block;
}

const StatBlock& ideal_memory_stats() {
    static const StatBlock block{"model.ideal_memory", counter_stats(true)};
    return block;
}

nlohmann::json dram_counters_json(const MemStats& stats) {
    nlohmann::json j = stats.to_json();
    auto drop_cache_fields = [](nlohmann::json& c) {
        for (const char* k : {"read_hits", "merged", "hit_rate"}) c.erase(k);
    };
    drop_cache_fields(j);
    for (auto& [kind, c] : j["by_kind"].items()) drop_cache_fields(c);
    return j;
}

nlohmann::json cache_config_json(const CacheConfig& c, const nlohmann::json& mshrs) {
    return {{"size_kib", c.size_kib}, {"ways", c.ways},     {"line_bytes", c.line_bytes},
            {"latency", c.latency},   {"mshrs", mshrs}, {"banks", c.banks}};
}

void dram_bandwidth_stats(StatsWriter& w, const DramConfig& c, double bytes, double cycles, double clock_ghz) {
    const double seconds = cycles / (clock_ghz * 1e9);
    const double peak = double(c.bytes_per_cycle) * c.channels * clock_ghz;  // GB/s
    const double achieved = seconds > 0 ? bytes / seconds / 1e9 : 0.0;
    w.set("bandwidth_gbps", achieved).set("peak_bandwidth_gbps", peak);
    w.set("bandwidth_utilization", peak > 0 ? achieved / peak : 0.0);
}

MemCounters MemStats::total() const {
    MemCounters t;
    for (const MemCounters& c : m_kinds) t += c;
    return t;
}

nlohmann::json MemStats::to_json() const {
    nlohmann::json j = counters_json(total());
    for (int k = 0; k < kDataKindCount; ++k)
        if (m_kinds[k].reads || m_kinds[k].writes) j["by_kind"][data_kind_name(DataKind(k))] = counters_json(m_kinds[k]);
    return j;
}

RTSIM_REGISTER_STAT_BLOCK(cache_stats)
RTSIM_REGISTER_STAT_BLOCK(dram_stats)
RTSIM_REGISTER_STAT_BLOCK(ideal_memory_stats)

}  // namespace rtsim
