#include "sim/report/report_block.h"

#include <algorithm>

namespace rtsim {

namespace {

std::vector<ReportBlock>& registry() {
    static std::vector<ReportBlock> blocks;
    return blocks;
}

}  // namespace

bool register_report_block(ReportBlock block) {
    registry().push_back(std::move(block));
    return true;
}

std::vector<const ReportBlock*> report_blocks() {
    std::vector<const ReportBlock*> out;
    for (const ReportBlock& b : registry()) out.push_back(&b);
    std::stable_sort(out.begin(), out.end(), [](const ReportBlock* a, const ReportBlock* b) { return a->order < b->order; });
    return out;
}

}  // namespace rtsim
