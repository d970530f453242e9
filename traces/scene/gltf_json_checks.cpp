// Checks on the raw bytes of a glTF file, made before tinygltf sees them: tinygltf recurses once
// per nesting level (a deep `extras` overflows the call stack) and reads any GLB version. The
// document's numbers and indices are checked in gltf_json_schema.cpp. Each check names the file.
#include "traces/scene/gltf_internal.h"

namespace rtsim::gltf {

namespace {

uint32_t le32(const unsigned char* p) {
    return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
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
