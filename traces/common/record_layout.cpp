#include "traces/common/record_layout.h"

#include <vector>

#include "traces/common/error.h"

namespace rtsim {

uint32_t FieldLayout::bytes() const {
    uint32_t n = element_bytes;
    for (uint32_t e : shape) n *= e;
    return n;
}

nlohmann::json layout_json(const RecordLayout& layout) {
    nlohmann::json out = nlohmann::json::array();
    for (const FieldLayout& f : layout)
        out.push_back({{"name", f.name}, {"type", f.type}, {"offset", f.offset}, {"shape", f.shape}});
    return out;
}

namespace {

uint32_t element_bytes_of(const std::string& type, const std::string& source) {
    static const std::vector<std::pair<std::string, uint32_t>> kTypes = {
        {"<f4", 4}, {"<f8", 8}, {"u1", 1}, {"<u2", 2}, {"<u4", 4}, {"<i4", 4}, {"<u8", 8}};
    for (const auto& [name, bytes] : kTypes)
        if (name == type) return bytes;
    throw Error(source + ": record field type '" + type + "' is not one of <f4 <f8 u1 <u2 <u4 <i4 <u8");
}

}  // namespace

RecordLayout layout_from_json(const nlohmann::json& j, const std::string& source) {
    require(j.is_array(), source + ": a record layout must be a list of fields");
    RecordLayout out;
    for (const nlohmann::json& f : j) {
        require(f.is_object() && f.contains("name") && f["name"].is_string() && f.contains("type") &&
                    f["type"].is_string() && f.contains("offset") && f["offset"].is_number_unsigned() &&
                    f.contains("shape") && f["shape"].is_array(),
                source + ": a record field needs name, type, offset and shape");
        FieldLayout fl;
        fl.name = f["name"].get<std::string>();
        fl.type = f["type"].get<std::string>();
        fl.offset = f["offset"].get<uint32_t>();
        for (const nlohmann::json& e : f["shape"]) {
            require(e.is_number_unsigned() && e.get<uint64_t>() > 0 && e.get<uint64_t>() < (1u << 16),
                    source + ": field '" + fl.name + "' has a bad array extent");
            fl.shape.push_back(e.get<uint32_t>());
        }
        fl.element_bytes = element_bytes_of(fl.type, source);
        out.push_back(std::move(fl));
    }
    return out;
}

uint32_t covered_bytes(const RecordLayout& layout, uint32_t record_bytes) {
    std::vector<bool> covered(record_bytes, false);
    for (const FieldLayout& f : layout)
        for (uint32_t b = f.offset; b < f.offset + f.bytes() && b < record_bytes; ++b) covered[b] = true;
    uint32_t n = 0;
    for (bool c : covered) n += c;
    return n;
}

}  // namespace rtsim
