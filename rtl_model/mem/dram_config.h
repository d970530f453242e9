#pragma once
// Configuration of the DRAM channels: banks and row buffers (model "banks", the default, at the
// approx and detailed levels) or plain channel bandwidth calendars (model "bandwidth").
#include <cstdint>

#include "rtl_model/common/choice.h"

namespace rtsim {

enum class PagePolicy : uint8_t { open = 0, close = 1 };
inline constexpr Choices<PagePolicy, 2> kPagePolicyChoices{{"open", "close"}};

enum class DramModel : uint8_t { banks = 0, bandwidth = 1 };

enum class DramScheduler : uint8_t { fcfs = 0, frfcfs = 1 };
inline constexpr Choices<DramScheduler, 2> kDramSchedulerChoices{{"fcfs", "frfcfs"}};
inline constexpr Choices<DramModel, 2> kDramModelChoices{{"banks", "bandwidth"}};

struct DramConfig {
    uint32_t channels = 2;          ///< independent channels, interleaved every interleave_bytes
    uint32_t bytes_per_cycle = 16;  ///< peak bandwidth of one channel in bytes per core cycle
    uint32_t latency = 120;         ///< cycles from request to first data, unloaded
    uint32_t interleave_bytes = 256;///< address interleaving granule across channels
    DramModel model = DramModel::banks;  ///< banks and row buffers, or bandwidth calendars only
    // Banks and row buffers: used with model = "banks" (docs/model.md, "DRAM").
    uint32_t banks = 16;            ///< banks per channel, each with one row buffer
    uint32_t row_bytes = 2048;      ///< row (page) size per bank
    PagePolicy page_policy = PagePolicy::open;  ///< open: rows stay open; close: auto-precharge
    uint32_t t_rcd = 14;            ///< activate to column command, core cycles
    uint32_t t_rp = 14;             ///< precharge, core cycles
    uint32_t t_cas = 14;            ///< column command to first data, core cycles
    // Second-order DDR limits, 0 = off (the default keeps the first-order bank model; the
    // `ddr4` modifier sets DDR4-2133's, docs/model.md "Banks and row buffers").
    uint32_t t_ras = 0;             ///< activate to precharge of the same bank, at least
    uint32_t t_rrd = 0;             ///< activate to activate of two banks of a channel, at least
    uint32_t t_faw = 0;             ///< window holding at most four activates of a channel
    uint32_t t_refi = 0;            ///< all-bank refresh interval of a channel (0: no refresh)
    uint32_t t_rfc = 0;             ///< refresh time: every bank busy and precharged
    uint32_t bank_groups = 1;       ///< bank groups per channel (bank b in group b mod groups)
    /// Bank-group interleaving: consecutive granules of this many bytes of a channel go to
    /// consecutive bank groups (0: off, a row's bytes stay in one bank and so in one group).
    uint32_t group_interleave_bytes = 0;
    uint32_t t_rrd_l = 0;           ///< activate to activate of two banks of one group (0: t_rrd)
    uint32_t t_ccd_l = 0;           ///< column to column of two accesses in one bank group
    uint32_t t_wtr = 0;             ///< end of a write's data to a read's column, on a channel (tWTR_S)
    uint32_t t_wtr_l = 0;           ///< the same within one bank group (tWTR_L; 0: t_wtr for all)
    uint32_t t_rtw = 0;             ///< a read's column to a write's column, on a channel
    uint32_t queue_entries = 0;     ///< requests a channel's controller holds at once (0: any)
    /// The controller's order: first come first served, or row hits first (FR-FCFS; open page)
    DramScheduler scheduler = DramScheduler::fcfs;

    template <class V>
    void visit(V& v) {
        v.field("channels", channels, "channels", "Independent DRAM channels", 1, 64);
        v.field("bytes_per_cycle", bytes_per_cycle, "B/cycle", "Peak bandwidth per channel, bytes per core cycle", 1, 4096);
        v.field("latency", latency, "cycles", "Unloaded access latency, request to data (model banks: of an access to a closed bank)", 1, 100000);
        v.choice("model", model, kDramModelChoices, "DRAM timing: banks and row buffers (hits, misses, conflicts) or channel bandwidth calendars only (every access costs latency)");
        v.field("interleave_bytes", interleave_bytes, "bytes", "Channel interleaving granule (power of two, >= line size)", 64, 1u << 20);
        v.field("banks", banks, "banks", "Banks per channel, one row buffer each (model banks)", 1, 256);
        v.field("row_bytes", row_bytes, "bytes", "Row (page) size of a bank (power of two; model banks)", 64, 1u << 20);
        v.choice("page_policy", page_policy, kPagePolicyChoices, "Row buffer policy: keep rows open (row hits) or precharge after each access (model banks)");
        v.field("t_rcd", t_rcd, "cycles", "Activate to column command, core cycles (model banks)", 0, 10000);
        v.field("t_rp", t_rp, "cycles", "Precharge time, core cycles (model banks)", 0, 10000);
        v.field("t_cas", t_cas, "cycles", "Column command to first data, core cycles (model banks)", 0, 10000);
        v.field("t_ras", t_ras, "cycles", "Activate to precharge of a bank, at least, core cycles (model banks; 0: no limit)", 0, 10000);
        v.field("t_rrd", t_rrd, "cycles", "Activate to activate of two banks of a channel, at least, core cycles (model banks; 0: no limit)", 0, 10000);
        v.field("t_faw", t_faw, "cycles", "Four-activate window: at most four activates of a channel in any window this long, core cycles (model banks; 0: no limit)", 0, 10000);
        v.field("t_refi", t_refi, "cycles", "All-bank refresh interval of a channel, core cycles (model banks; 0: no refresh)", 0, 10000000);
        v.field("t_rfc", t_rfc, "cycles", "Refresh time: every bank of the channel busy and precharged, core cycles (model banks, with t_refi)", 0, 100000);
        v.field("bank_groups", bank_groups, "groups", "Bank groups per channel, bank b in group b mod bank_groups (model banks; 1: no groups; must divide dram.banks)", 1, 256);
        v.field("group_interleave_bytes", group_interleave_bytes, "bytes", "Bank-group interleaving granule: consecutive granules of a channel go to consecutive bank groups, so streaming lines alternate groups and their column commands are spaced by tCCD_S (the bus) rather than t_ccd_l (model banks; power of two, at least the line size, at most dram.row_bytes; 0: off, a row's bytes in one bank)", 0, 1u << 20);
        v.field("t_rrd_l", t_rrd_l, "cycles", "Activate to activate of two banks in one bank group, at least, core cycles (model banks; t_rrd is then the other groups' figure; 0: t_rrd for all)", 0, 10000);
        v.field("t_ccd_l", t_ccd_l, "cycles", "Column to column of two accesses in one bank group, at least, core cycles (model banks; other groups are spaced by their bursts on the bus; 0: no limit)", 0, 10000);
        v.field("t_wtr", t_wtr, "cycles", "Write-to-read turnaround: end of a write's data to a read's column command on the channel, core cycles (tWTR_S with t_wtr_l set; model banks; 0: none)", 0, 10000);
        v.field("t_wtr_l", t_wtr_l, "cycles", "Write-to-read turnaround within one bank group: end of a write's data to a read's column command in the same group, core cycles (tWTR_L; t_wtr is then the other groups' figure, tWTR_S; model banks; 0: t_wtr for all)", 0, 10000);
        v.field("t_rtw", t_rtw, "cycles", "Read-to-write turnaround: a read's column command to a write's on the channel, core cycles (model banks; 0: none)", 0, 10000);
        v.field("queue_entries", queue_entries, "requests", "Requests a channel's controller holds at once, arrival to data; one arriving at a full queue waits for the first to leave (model banks; 0: no limit)", 0, 4096);
        v.choice("scheduler", scheduler, kDramSchedulerChoices, "Controller order (model banks, open page): fcfs serves a bank's requests as they arrive; frfcfs serves a request to a row a booked access leaves open right after that access, ahead of the booked accesses that change the row, which move back (Rixner et al. 2000's first-ready FCFS; docs/model.md)");
    }
};

}  // namespace rtsim
