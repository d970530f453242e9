#include "traces/accel/accel_io.h"

#include <string>

#include "traces/common/error.h"

namespace rtsim {

using nlohmann::json;

void write_accel_image(TraceWriter& writer, const AccelImage& image) {
    require(image.regions.size() <= kMaxRegionSections, "accel image has more than 100 regions");
    const std::string text = image.descriptor().dump();
    writer.append(SectionKind::accel, text.data(), text.size(), 1);
    for (size_t i = 0; i < image.regions.size(); ++i) {
        const Region& r = image.regions[i];
        if (r.count == 0) continue;  // an empty region has no section (the descriptor lists it)
        writer.append(region_section(uint32_t(i)), r.bytes.data(), r.count, r.record_bytes);
    }
}

nlohmann::json read_accel_descriptor(TraceReader& reader) {
    const std::string& path = reader.path();
    const SectionInfo& info = reader.section(SectionKind::accel);
    require(info.record_count <= (64u << 20), path + ": section ACCL is larger than 64 MiB");
    std::string text(info.record_count, '\0');
    reader.read(SectionKind::accel, 0, info.record_count, text.data());
    // Bounded nesting: the descriptor is a few levels deep; deeper input is refused, not recursed.
    int depth = 0, max_depth = 0;
    for (char c : text) {
        if (c == '{' || c == '[') max_depth = std::max(max_depth, ++depth);
        else if (c == '}' || c == ']') --depth;
    }
    require(max_depth <= 32, path + ": section ACCL: descriptor nested deeper than 32 levels");
    json d = json::parse(text, nullptr, false);
    require(!d.is_discarded(), path + ": section ACCL: the descriptor is not valid JSON");
    return d;
}

AccelImage read_accel_image(TraceReader& reader) {
    const std::string& path = reader.path();
    AccelImage image = AccelImage::from_descriptor(read_accel_descriptor(reader), path);
    require(image.regions.size() <= kMaxRegionSections, path + ": section ACCL: more than 100 regions");
    for (size_t i = 0; i < image.regions.size(); ++i) {
        Region& r = image.regions[i];
        const SectionKind kind = region_section(uint32_t(i));
        const std::string where = path + ": region '" + r.name + "' (section " + section_name(kind) + ")";
        if (r.count == 0) {
            require(!reader.has(kind), where + ": present although the descriptor says it is empty");
            continue;
        }
        require(reader.has(kind), where + ": missing");
        const SectionInfo& s = reader.section(kind);
        require(s.record_bytes == r.record_bytes && s.record_count == r.count,
                where + ": holds " + std::to_string(s.record_count) + " records of " + std::to_string(s.record_bytes) +
                    " bytes, the descriptor says " + std::to_string(r.count) + " of " + std::to_string(r.record_bytes));
        r.bytes.resize(r.count * r.record_bytes, false);  // every byte is read next
        reader.read(kind, 0, r.count, r.bytes.data());
    }
    return image;
}

}  // namespace rtsim
