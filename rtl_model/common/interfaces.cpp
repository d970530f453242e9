#include "rtl_model/common/interfaces.h"

namespace rtsim {

const char* data_kind_name(DataKind kind) {
    switch (kind) {
        case DataKind::node: return "node";
        case DataKind::triangle: return "triangle";
        case DataKind::ray: return "ray";
        case DataKind::hit: return "hit";
        case DataKind::stack: return "stack";
        case DataKind::ray_buffer: return "ray_buffer";
    }
    return "unknown";
}

}  // namespace rtsim
