// Checks on the raw bytes and JSON of a glTF file, made before tinygltf sees them: tinygltf
// recurses once per nesting level (a deep `extras` overflows the call stack), silently replaces
// a negative byteOffset or byteStride by 0, reads any GLB version and never range-checks texture
// indices. Each check names the file and the element.
#include <cmath>

#include <nlohmann/json.hpp>

#include "traces/scene/gltf_internal.h"

namespace rtsim::gltf {

namespace {

using nlohmann::json;

uint32_t le32(const unsigned char* p) {
    return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

/// "bufferView 3 'name'" for element `i` of array `kind` of the document.
std::string json_element(const json& doc, const char* array, const char* kind, size_t i) {
    const json& e = doc[array][i];
    auto name = e.is_object() ? e.find("name") : e.end();
    return element(kind, i, name != e.end() && name->is_string() ? name->get<std::string>() : "");
}

/// Field `key` of `object`, if present, must be an integer >= minimum.
void check_integer(const std::string& file, const json& object, const char* key, int64_t minimum,
                   const std::string& where) {
    auto it = object.find(key);
    if (it == object.end()) return;
    const bool integer = it->is_number_integer() ||
                         (it->is_number_float() && std::isfinite(it->get<double>()) &&
                          std::trunc(it->get<double>()) == it->get<double>());
    if (!integer || it->get<double>() < double(minimum))
        throw Error(file + ": " + where + ": " + key + " is " + it->dump() + " (must be an integer >= " +
                    std::to_string(minimum) + ")");
}

/// A textureInfo object (anything with an "index" under a key ending in "Texture").
void check_texture_info(const std::string& file, const json& info, size_t textures, const std::string& where) {
    if (!info.is_object() || !info.contains("index")) return;
    const json& index = info["index"];
    if (!index.is_number_integer() || index.get<int64_t>() < 0 || uint64_t(index.get<int64_t>()) >= textures)
        throw Error(file + ": " + where + ": texture index " + index.dump() + " out of range (" +
                    std::to_string(textures) + " textures)");
}

/// Every textureInfo under `value` (core slots and extensions alike), depth-first.
void check_textures_under(const std::string& file, const json& value, size_t textures, const std::string& where) {
    if (!value.is_object()) return;
    for (auto it = value.begin(); it != value.end(); ++it) {
        const std::string& key = it.key();
        std::string path = where + "." + key;
        bool texture_key = key.size() >= 7 && key.compare(key.size() - 7, 7, "Texture") == 0;
        if (texture_key) check_texture_info(file, it.value(), textures, path);
        else if (key != "extras") check_textures_under(file, it.value(), textures, path);
    }
}

void check_array_refs(const std::string& file, const json& doc) {
    auto size_of = [&doc](const char* key) {
        auto it = doc.find(key);
        return it != doc.end() && it->is_array() ? it->size() : size_t(0);
    };
    const size_t textures = size_of("textures"), images = size_of("images"), samplers = size_of("samplers");
    for (size_t i = 0; i < size_of("materials"); ++i)
        check_textures_under(file, doc["materials"][i], textures, json_element(doc, "materials", "material", i));
    for (size_t i = 0; i < textures; ++i) {
        const json& t = doc["textures"][i];
        if (!t.is_object()) continue;
        std::string where = json_element(doc, "textures", "texture", i);
        struct Ref {
            const char* key;
            size_t count;
            const char* of;
        };
        for (const Ref& r : {Ref{"source", images, "images"}, Ref{"sampler", samplers, "samplers"}}) {
            auto it = t.find(r.key);
            if (it == t.end()) continue;
            if (!it->is_number_integer() || it->get<int64_t>() < 0 || uint64_t(it->get<int64_t>()) >= r.count)
                throw Error(file + ": " + where + ": " + r.key + " " + it->dump() + " out of range (" +
                            std::to_string(r.count) + " " + r.of + ")");
        }
    }
}

}  // namespace

void check_json_depth(const std::string& file, const unsigned char* text, size_t size) {
    // Brackets outside strings; escapes inside strings skip the next byte.
    size_t depth = 0;
    bool in_string = false;
    for (size_t i = 0; i < size; ++i) {
        const unsigned char c = text[i];
        if (in_string) {
            if (c == '\\') ++i;
            else if (c == '"') in_string = false;
        } else if (c == '"') {
            in_string = true;
        } else if (c == '[' || c == '{') {
            if (++depth > kMaxJsonDepth)
                throw Error(file + ": JSON nested deeper than " + std::to_string(kMaxJsonDepth) +
                            " levels (at byte " + std::to_string(i) + "); refused before parsing");
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
}

void check_raw_document(const std::string& file, const unsigned char* text, size_t size) {
    json doc = json::parse(text, text + size, nullptr, false);
    if (doc.is_discarded() || !doc.is_object()) return;  // tinygltf reports the parse error
    auto each = [&](const char* array, const char* kind, auto&& check) {
        auto it = doc.find(array);
        if (it == doc.end() || !it->is_array()) return;
        for (size_t i = 0; i < it->size(); ++i)
            if ((*it)[i].is_object()) check((*it)[i], json_element(doc, array, kind, i));
    };
    each("buffers", "buffer", [&](const json& b, const std::string& where) {
        check_integer(file, b, "byteLength", 1, where);  // glTF 2.0: minimum 1
    });
    each("bufferViews", "bufferView", [&](const json& v, const std::string& where) {
        check_integer(file, v, "byteOffset", 0, where);
        check_integer(file, v, "byteLength", 1, where);
        check_integer(file, v, "byteStride", 0, where);
    });
    each("accessors", "accessor", [&](const json& a, const std::string& where) {
        check_integer(file, a, "byteOffset", 0, where);
        check_integer(file, a, "count", 0, where);
    });
    check_array_refs(file, doc);
}

GlbChunks check_glb(const std::string& file, const unsigned char* data, size_t size) {
    if (size < 20) throw Error(file + ": truncated GLB: " + std::to_string(size) + " bytes, less than the 20-byte header");
    const uint32_t version = le32(data + 4), length = le32(data + 8);
    if (version != 2)
        throw Error(file + ": GLB container version " + std::to_string(version) +
                    " is not supported (glTF 2.0 uses GLB version 2)");
    if (length != size)
        throw Error(file + ": GLB header says " + std::to_string(length) + " bytes, the file has " + std::to_string(size));
    const uint32_t json_bytes = le32(data + 12), json_type = le32(data + 16);
    if (json_type != 0x4E4F534Au || json_bytes == 0 || json_bytes > size - 20)
        throw Error(file + ": GLB: first chunk is not a JSON chunk inside the file (" + std::to_string(json_bytes) +
                    " bytes at offset 20)");
    return GlbChunks{data + 20, json_bytes};
}

std::string valid_utf8(const std::string& text) {
    // Well-formed UTF-8 (RFC 3629) is kept; every other byte becomes "\xNN".
    std::string out;
    out.reserve(text.size());
    const auto* s = reinterpret_cast<const unsigned char*>(text.data());
    const size_t n = text.size();
    for (size_t i = 0; i < n;) {
        const unsigned char c = s[i];
        size_t len = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
        bool ok = len > 0 && i + len <= n && !(c == 0xC0 || c == 0xC1 || c > 0xF4);
        for (size_t k = 1; ok && k < len; ++k) ok = (s[i + k] & 0xC0) == 0x80;
        if (ok && len == 3) {  // no overlongs, no surrogates
            const unsigned char d = s[i + 1];
            ok = !(c == 0xE0 && d < 0xA0) && !(c == 0xED && d >= 0xA0);
        }
        if (ok && len == 4) {
            const unsigned char d = s[i + 1];
            ok = !(c == 0xF0 && d < 0x90) && !(c == 0xF4 && d >= 0x90);
        }
        if (ok) {
            out.append(text, i, len);
            i += len;
        } else {
            static const char* hex = "0123456789abcdef";
            out += "\\x";
            out += hex[c >> 4];
            out += hex[c & 15];
            ++i;
        }
    }
    return out;
}

}  // namespace rtsim::gltf
