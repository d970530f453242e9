#include "rtl_model/top/model_config.h"

#include <string>

#include "traces/common/error.h"

namespace rtsim {

namespace {

bool power_of_two(uint64_t x) { return x && !(x & (x - 1)); }

void validate_cache(const CacheConfig& c, const char* name) {
    std::string p = std::string("config: '") + name;
    require(power_of_two(c.line_bytes), p + ".line_bytes' must be a power of two");
    uint64_t lines = c.lines();
    require(lines >= c.ways && lines % c.ways == 0,
            p + ".size_kib' must hold a whole number of sets of " + std::to_string(c.ways) + " ways of " +
                std::to_string(c.line_bytes) + "-byte lines");
    require(power_of_two(lines / c.ways), p + ".size_kib' / (ways x line_bytes) must be a power of two (sets)");
}

}  // namespace

const PipelineConfig& ModelConfig::pipeline(OpKind kind) const {
    switch (kind) {
        case OpKind::box: return box;
        case OpKind::triangle: return triangle;
        case OpKind::anyhit: return anyhit;
        case OpKind::cell: return cell;
        case OpKind::transform: return transform;
        case OpKind::plane: return plane;
        case OpKind::obb: return obb;
        case OpKind::sphere: return sphere;
        case OpKind::capsule: return capsule;
        default: break;
    }
    throw Error(std::string("config: no pipeline is configured for '") + op_kind_name(kind) + "' operations");
}

void validate_model(const ModelConfig& config) {
    validate_cache(config.l1, "l1");
    validate_cache(config.l2, "l2");
    require(config.l1.line_bytes == config.l2.line_bytes,
            "config: 'l1.line_bytes' (" + std::to_string(config.l1.line_bytes) + ") must equal 'l2.line_bytes' (" +
                std::to_string(config.l2.line_bytes) + ")");
    require(power_of_two(config.dram.interleave_bytes) && config.dram.interleave_bytes >= config.l2.line_bytes,
            "config: 'dram.interleave_bytes' must be a power of two and at least the line size");
    require(power_of_two(config.dram.row_bytes) && power_of_two(config.dram.banks),
            "config: 'dram.row_bytes' and 'dram.banks' must be powers of two (address bit fields)");
    const bool banks_run = config.dram.model == DramModel::banks && !config.ideal_memory && config.timed();
    require(!banks_run || config.dram.latency >= config.dram.t_rcd + config.dram.t_cas,
            "config: 'dram.latency' must be at least dram.t_rcd + dram.t_cas with dram.model banks (it is the "
            "latency of an access to a closed bank); raise dram.latency, lower dram.t_rcd/dram.t_cas, or set "
            "dram.model=bandwidth");
    require(config.dram.banks % config.dram.bank_groups == 0,
            "config: 'dram.bank_groups' (" + std::to_string(config.dram.bank_groups) + ") must divide 'dram.banks' (" +
                std::to_string(config.dram.banks) + "): every group holds as many banks");
    const uint32_t gi = config.dram.group_interleave_bytes;
    require(gi == 0 || (power_of_two(gi) && gi >= config.l2.line_bytes && gi <= config.dram.row_bytes),
            "config: 'dram.group_interleave_bytes' (" + std::to_string(gi) +
                ") must be 0 or a power of two from the line size to 'dram.row_bytes'");
        require(config.dram.t_refi == 0 || config.dram.t_rfc < config.dram.t_refi,
            "config: 'dram.t_rfc' (" + std::to_string(config.dram.t_rfc) + ") must be below 'dram.t_refi' (" +
                std::to_string(config.dram.t_refi) + "): a channel must be free between refreshes");
    require(config.dram.t_refi != 0 || config.dram.t_rfc == 0,
            "config: 'dram.t_rfc' needs 'dram.t_refi' (the refresh interval); set both or neither");
}

}  // namespace rtsim
