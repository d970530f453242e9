#include "traces/common/data_kind.h"

#include <cstring>

namespace rtsim {

namespace {
constexpr const char* kNames[kDataKindCount] = {"node", "triangle", "ray", "hit", "stack",
                                                "ray_buffer", "prim_ref", "cell", "instance"};
}

const char* data_kind_name(DataKind kind) {
    const auto i = static_cast<int>(kind);
    return i < kDataKindCount ? kNames[i] : "unknown";
}

bool parse_data_kind(const char* name, DataKind* kind) {
    for (int i = 0; i < kDataKindCount; ++i)
        if (std::strcmp(name, kNames[i]) == 0) {
            *kind = static_cast<DataKind>(i);
            return true;
        }
    return false;
}

}  // namespace rtsim
