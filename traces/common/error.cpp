#include "traces/common/error.h"

namespace rtsim {

void require(bool condition, const std::string& message) {
    if (!condition) throw Error(message);
}

}  // namespace rtsim
