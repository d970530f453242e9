#include "traces/accel/accel_image.h"

#include <algorithm>

#include "traces/common/error.h"

namespace rtsim {

using nlohmann::json;

Region& AccelImage::add_region(const std::string& name, DataKind kind, uint32_t record_bytes, uint64_t count,
                               RecordLayout layout, bool zero) {
    require(!has_region(name), "accel image '" + this->kind + "': region '" + name + "' added twice");
    Region r;
    r.name = name;
    r.kind = kind;
    r.record_bytes = record_bytes;
    r.count = count;
    r.layout = std::move(layout);
    r.bytes.resize(count * record_bytes, zero);
    regions.push_back(std::move(r));
    return regions.back();
}

bool AccelImage::has_region(const std::string& name) const {
    return std::any_of(regions.begin(), regions.end(), [&](const Region& r) { return r.name == name; });
}

const Region& AccelImage::region(const std::string& name) const {
    for (const Region& r : regions)
        if (r.name == name) return r;
    throw Error("accel image '" + kind + "' has no region '" + name + "'");
}

Region& AccelImage::region(const std::string& name) {
    return const_cast<Region&>(static_cast<const AccelImage*>(this)->region(name));
}

void AccelImage::place_regions() {
    uint64_t next = kBase;
    for (Region& r : regions) {
        r.base = next;
        next += std::max(kGranule, round_up(r.size_bytes(), kGranule));
    }
}

uint64_t AccelImage::end_address() const {
    if (regions.empty()) return kBase;
    const Region& last = regions.back();
    return last.base + std::max(kGranule, round_up(last.size_bytes(), kGranule));
}

uint64_t AccelImage::footprint_bytes() const {
    uint64_t bytes = 0;
    for (const Region& r : regions) bytes += r.size_bytes();
    return bytes;
}

namespace {
json vec3(const Vec3& v) { return json::array({v.x, v.y, v.z}); }
}  // namespace

json AccelImage::descriptor() const {
    json rs = json::array();
    for (const Region& r : regions) {
        rs.push_back({{"name", r.name},
                      {"kind", data_kind_name(r.kind)},
                      {"record_bytes", r.record_bytes},
                      {"count", r.count},
                      {"base", r.base}});
        if (!r.layout.empty()) rs.back()["fields"] = layout_json(r.layout);
    }
    return {{"kind", kind},
            {"params", params},
            {"stats", stats},
            {"bounds", {{"lo", vec3(bounds.lo)}, {"hi", vec3(bounds.hi)}}},
            {"regions", rs}};
}

AccelImage AccelImage::from_descriptor(const json& d, const std::string& source) {
    const std::string where = source + ": acceleration-structure descriptor (section ACCL)";
    auto need = [&](const json& obj, const char* key, bool (json::*is)() const, const char* what) -> const json& {
        require(obj.is_object() && obj.contains(key) && (obj.at(key).*is)(),
                where + ": '" + key + "' is missing or not " + what);
        return obj.at(key);
    };
    auto count_of = [&](const json& obj, const char* key, const std::string& at) -> uint64_t {
        require(obj.contains(key) && obj.at(key).is_number_integer() &&
                    (obj.at(key).is_number_unsigned() || obj.at(key).get<int64_t>() >= 0),
                where + ": '" + at + "." + key + "' is missing or not a non-negative integer");
        return obj.at(key).get<uint64_t>();
    };
    AccelImage image;
    image.kind = need(d, "kind", &json::is_string, "a string").get<std::string>();
    image.params = need(d, "params", &json::is_object, "an object");
    image.stats = need(d, "stats", &json::is_object, "an object");
    const json& b = need(d, "bounds", &json::is_object, "an object");
    for (const char* side : {"lo", "hi"}) {
        const json& v = need(b, side, &json::is_array, "an array");
        require(v.size() == 3 && std::all_of(v.begin(), v.end(), [](const json& x) { return x.is_number(); }),
                where + ": 'bounds." + side + "' must be 3 numbers");
        Vec3& out = side[0] == 'l' ? image.bounds.lo : image.bounds.hi;
        for (int a = 0; a < 3; ++a) out[a] = v[a].get<float>();
    }
    const json& rs = need(d, "regions", &json::is_array, "an array");
    for (size_t i = 0; i < rs.size(); ++i) {
        const json& r = rs[i];
        const std::string at = "regions[" + std::to_string(i) + "]";
        require(r.is_object(), where + ": '" + at + "' must be an object");
        const std::string name = need(r, "name", &json::is_string, "a string").get<std::string>();
        const std::string kind = need(r, "kind", &json::is_string, "a string").get<std::string>();
        DataKind dk;
        require(parse_data_kind(kind.c_str(), &dk), where + ": '" + at + ".kind' = '" + kind + "' is not a data kind");
        const uint64_t rb = count_of(r, "record_bytes", at), count = count_of(r, "count", at),
                       base = count_of(r, "base", at);
        require(rb >= 1 && rb <= 4096, where + ": '" + at + ".record_bytes' must be in [1, 4096]");
        require(count <= (1ull << 40), where + ": '" + at + ".count' is larger than 2^40");
        require(!image.has_region(name), where + ": region '" + name + "' listed twice");
        Region region;
        region.name = name;
        region.kind = dk;
        region.record_bytes = uint32_t(rb);
        region.count = count;
        region.base = base;
        if (r.contains("fields")) {
            region.layout = layout_from_json(r.at("fields"), where + ": '" + at + ".fields'");
            for (const FieldLayout& f : region.layout)
                require(f.offset + f.bytes() <= rb, where + ": '" + at + ".fields': field '" + f.name +
                                                        "' runs past the " + std::to_string(rb) + "-byte record");
        }
        image.regions.push_back(std::move(region));  // bytes are allocated by the reader
    }
    // The addresses must be the ones place_regions() gives: the model relies on the layout.
    AccelImage placed;
    placed.regions.resize(image.regions.size());
    for (size_t i = 0; i < image.regions.size(); ++i) {
        placed.regions[i].count = image.regions[i].count;
        placed.regions[i].record_bytes = image.regions[i].record_bytes;
    }
    placed.place_regions();
    for (size_t i = 0; i < image.regions.size(); ++i)
        require(placed.regions[i].base == image.regions[i].base,
                where + ": region '" + image.regions[i].name + "' is not at its address");
    return image;
}

}  // namespace rtsim
