#include "traces/common/work_counts.h"

#include <string>

#include "traces/common/error.h"

namespace rtsim {

WorkField work_field_of(OpKind kind) {
    for (size_t i = 0; i < kWorkFields.size(); ++i)
        if (kWorkFields[i].tests_of == kind) return WorkField(i);
    throw Error(std::string("no work counter counts '") + op_kind_name(kind) + "' tests (traces/common/work_counts.h)");
}

double plan_step_work(const WorkCounts& w) {
    double n = 0;
    for (const WorkFieldInfo& f : kWorkFields)
        if (f.plan_step) n += w.*f.member;
    return n;
}

}  // namespace rtsim
