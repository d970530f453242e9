#include "traces/common/data_kind.h"

#include <cstring>

namespace rtsim {

const char* data_kind_name(DataKind kind) {
    const auto i = static_cast<size_t>(kind);
    return i < kDataKinds.size() ? kDataKinds[i].name : "unknown";
}

bool parse_data_kind(const char* name, DataKind* kind) {
    for (size_t i = 0; i < kDataKinds.size(); ++i)
        if (std::strcmp(name, kDataKinds[i].name) == 0) {
            *kind = static_cast<DataKind>(i);
            return true;
        }
    return false;
}

}  // namespace rtsim
