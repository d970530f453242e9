// glTF numbers read by value (gltf_internal.h, normalize_document). JSON does not distinguish
// 3 from 3.0, and exporters write either; tinygltf reads an integer field only when the JSON
// number is written without a fraction and otherwise silently keeps its default (byteOffset 0,
// no camera, the default material). Here every integer field the glTF 2.0 schema declares is
// checked before tinygltf sees the document: an integer-valued number becomes that integer, a
// fractional, non-numeric or out-of-range one is refused naming the file, element and key, and
// every index is checked against the array it points into. External buffer and image files must
// be regular files.
#include <cmath>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "traces/scene/gltf_internal.h"

namespace rtsim::gltf {

namespace {

using nlohmann::json;
namespace fs = std::filesystem;

/// Largest magnitude a double holds exactly; beyond it "integer-valued" means nothing.
constexpr double kExactLimit = 9007199254740992.0;  // 2^53
constexpr int64_t kAny = int64_t(kExactLimit);

class Normalizer {
public:
    Normalizer(const std::string& file, json& doc) : m_file(file), m_doc(doc) {}
    bool changed() const { return m_changed; }

    void run() {
        // Arrays before what points into them: buffers, views, accessors, then their users.
        each("buffers", "buffer", [&](json& b, const std::string& w) {
            integer(b, "byteLength", w, 1, kAny);
            uri(b, w);
        });
        each("bufferViews", "bufferView", [&](json& v, const std::string& w) { buffer_view(v, w); });
        each("accessors", "accessor", [&](json& a, const std::string& w) { accessor(a, w); });
        each("images", "image", [&](json& i, const std::string& w) {
            index(i, "bufferView", w, "bufferViews");
            uri(i, w);
        });
        each("samplers", "sampler", [&](json& s, const std::string& w) {
            for (const char* key : {"magFilter", "minFilter", "wrapS", "wrapT"}) integer(s, key, w, 0, 65535);
        });
        each("textures", "texture", [&](json& t, const std::string& w) {
            index(t, "sampler", w, "samplers");
            index(t, "source", w, "images");
        });
        each("materials", "material", [&](json& m, const std::string& w) { texture_infos(m, w); });
        each("meshes", "mesh", [&](json& m, const std::string& w) { mesh(m, w); });
        each("nodes", "node", [&](json& n, const std::string& w) { node(n, w); });
        each("scenes", "scene", [&](json& s, const std::string& w) { index_list(s, "nodes", w, "nodes"); });
        index(m_doc, "scene", "the document", "scenes");
        each("skins", "skin", [&](json& s, const std::string& w) {
            index(s, "inverseBindMatrices", w, "accessors");
            index(s, "skeleton", w, "nodes");
            index_list(s, "joints", w, "nodes");
        });
        each("animations", "animation", [&](json& a, const std::string& w) { animation(a, w); });
    }

private:
    [[noreturn]] void fail(const std::string& where, const std::string& what) const {
        throw Error(m_file + ": " + where + ": " + what);
    }

    /// Elements of top-level array `array`; each must be an object.
    template <class F>
    void each(const char* array, const char* kind, F&& f) {
        auto it = m_doc.find(array);
        if (it == m_doc.end()) return;
        if (!it->is_array()) fail("the document", std::string(array) + " is not an array");
        for (size_t i = 0; i < it->size(); ++i) {
            json& e = (*it)[i];
            auto name = e.is_object() ? e.find("name") : e.end();
            std::string where =
                element(kind, i, name != e.end() && name->is_string() ? name->get<std::string>() : "");
            if (!e.is_object()) fail(where, "is " + e.dump() + ", not an object");
            f(e, where);
        }
    }

    /// Size of a top-level array (0 when absent).
    size_t count(const char* array) const {
        auto it = m_doc.find(array);
        return it != m_doc.end() && it->is_array() ? it->size() : 0;
    }

    /// `v` as an integer in [lo, hi]; an integer-valued float is rewritten as that integer.
    int64_t as_integer(json& v, const std::string& where, const std::string& key, int64_t lo, int64_t hi) {
        const std::string must = " (must be an integer in " + std::to_string(lo) + ".." +
                                 (hi == kAny ? std::string("2^53") : std::to_string(hi)) + ")";
        double d = 0.0;
        if (v.is_number_unsigned()) d = double(v.get<uint64_t>());
        else if (v.is_number()) d = v.get<double>();
        else fail(where, key + " is " + v.dump() + must);
        if (!std::isfinite(d) || std::trunc(d) != d) fail(where, key + " is " + v.dump() + must);
        if (d < double(lo) || d > double(hi)) fail(where, key + " is " + v.dump() + must);
        if (v.is_number_float()) {
            v = int64_t(d);
            m_changed = true;
        }
        return int64_t(d);
    }

    void integer(json& object, const char* key, const std::string& where, int64_t lo, int64_t hi) {
        auto it = object.find(key);
        if (it != object.end()) as_integer(*it, where, key, lo, hi);
    }

    /// "mesh" for "meshes", "bufferView" for "bufferViews".
    static std::string singular(const std::string& array) {
        if (array.size() > 3 && array.compare(array.size() - 3, 3, "hes") == 0) return array.substr(0, array.size() - 2);
        return array.substr(0, array.size() - 1);
    }

    /// `v` as an index into top-level array `array`.
    void check_index(json& v, const std::string& where, const std::string& key, const char* array,
                     size_t size) {
        const int64_t i = as_integer(v, where, key, -kAny, kAny);
        if (i < 0 || uint64_t(i) >= size)
            fail(where, key + ": " + singular(array) + " index " + std::to_string(i) + " out of range (" +
                            std::to_string(size) + " " + array + ")");
    }

    void index(json& object, const char* key, const std::string& where, const char* array) {
        auto it = object.find(key);
        if (it != object.end()) check_index(*it, where, key, array, count(array));
    }

    void index_list(json& object, const char* key, const std::string& where, const char* array) {
        auto it = object.find(key);
        if (it == object.end()) return;
        if (!it->is_array()) fail(where, std::string(key) + " is " + it->dump() + " (must be an array of indices)");
        for (size_t i = 0; i < it->size(); ++i)
            check_index((*it)[i], where, std::string(key) + "[" + std::to_string(i) + "]", array, count(array));
    }

    /// Every value of object `key` (attributes, morph targets) is an accessor index.
    void accessor_map(json& object, const std::string& where, const std::string& what) {
        if (!object.is_object()) fail(where, what + " is " + object.dump() + " (must be an object of accessor indices)");
        for (auto it = object.begin(); it != object.end(); ++it)
            check_index(it.value(), where, what + "." + it.key(), "accessors", count("accessors"));
    }

    /// Optional sub-object `key`; when present it must be an object.
    json* object_at(json& parent, const char* key, const std::string& where) {
        auto it = parent.find(key);
        if (it == parent.end()) return nullptr;
        if (!it->is_object()) fail(where, std::string(key) + " is " + it->dump() + " (must be an object)");
        return &*it;
    }

    void numbers(json& object, const char* key, const std::string& where, size_t n) {
        auto it = object.find(key);
        if (it == object.end()) return;
        bool ok = it->is_array() && it->size() == n;
        for (size_t i = 0; ok && i < n; ++i) ok = (*it)[i].is_number() && std::isfinite((*it)[i].get<double>());
        if (!ok)
            fail(where, std::string(key) + " is " + it->dump().substr(0, 200) + " (must be an array of " +
                            std::to_string(n) + " finite numbers)");
    }

    /// An external file named by `uri` must be a regular file: tinygltf reads it whole, so a
    /// folder ("."), a FIFO or /dev/zero would fail obscurely, block or read without end.
    void uri(json& object, const std::string& where) {
        auto it = object.find("uri");
        if (it == object.end()) return;
        if (!it->is_string()) fail(where, "uri is " + it->dump().substr(0, 200) + " (must be a string)");
        const std::string& u = it->get_ref<const std::string&>();
        if (u.rfind("data:", 0) == 0) return;
        std::error_code ec;
        const fs::path path = fs::path(m_file).parent_path() / u;
        const fs::file_status status = fs::status(path, ec);
        if (!fs::exists(status)) return;  // tinygltf names a missing file
        if (fs::is_directory(status)) fail(where, "uri '" + u + "' is a folder, not a file");
        if (!fs::is_regular_file(status))
            fail(where, "uri '" + u + "' is not a regular file (a FIFO, device or socket)");
    }

    void node(json& n, const std::string& where) {
        index(n, "camera", where, "cameras");
        index(n, "mesh", where, "meshes");
        index(n, "skin", where, "skins");
        index_list(n, "children", where, "nodes");
        numbers(n, "matrix", where, 16);
        numbers(n, "translation", where, 3);
        numbers(n, "rotation", where, 4);
        numbers(n, "scale", where, 3);
        json* ext = object_at(n, "extensions", where);
        if (ext == nullptr) return;
        if (json* inst = object_at(*ext, "EXT_mesh_gpu_instancing", where + ": extensions")) {
            auto attrs = inst->find("attributes");
            if (attrs == inst->end()) fail(where, "EXT_mesh_gpu_instancing has no attributes object");
            accessor_map(*attrs, where, "EXT_mesh_gpu_instancing.attributes");
        }
        if (json* light = object_at(*ext, "KHR_lights_punctual", where + ": extensions")) {
            auto it = light->find("light");
            if (it == light->end()) fail(where, "KHR_lights_punctual has no light index");
            check_index(*it, where, "KHR_lights_punctual.light", "lights", light_count());
        }
    }

    size_t light_count() const {
        auto ext = m_doc.find("extensions");
        if (ext == m_doc.end() || !ext->is_object()) return 0;
        auto punctual = ext->find("KHR_lights_punctual");
        if (punctual == ext->end() || !punctual->is_object()) return 0;
        auto lights = punctual->find("lights");
        return lights != punctual->end() && lights->is_array() ? lights->size() : 0;
    }

    void mesh(json& m, const std::string& where) {
        auto prims = m.find("primitives");
        if (prims == m.end()) return;
        if (!prims->is_array()) fail(where, "primitives is " + prims->dump().substr(0, 200) + " (must be an array)");
        for (size_t p = 0; p < prims->size(); ++p) {
            json& prim = (*prims)[p];
            const std::string w = where + " primitive " + std::to_string(p);
            if (!prim.is_object()) fail(w, "is " + prim.dump() + ", not an object");
            if (auto a = prim.find("attributes"); a != prim.end()) accessor_map(*a, w, "attributes");
            index(prim, "indices", w, "accessors");
            index(prim, "material", w, "materials");
            integer(prim, "mode", w, 0, 6);
            if (auto t = prim.find("targets"); t != prim.end()) {
                if (!t->is_array()) fail(w, "targets is " + t->dump().substr(0, 200) + " (must be an array)");
                for (size_t k = 0; k < t->size(); ++k) accessor_map((*t)[k], w, "targets[" + std::to_string(k) + "]");
            }
        }
    }

    void accessor(json& a, const std::string& where) {
        index(a, "bufferView", where, "bufferViews");
        integer(a, "byteOffset", where, 0, kAny);
        integer(a, "componentType", where, 5120, 5130);
        integer(a, "count", where, 0, kAny);
        json* sparse = object_at(a, "sparse", where);
        if (sparse == nullptr) return;
        integer(*sparse, "count", where + " sparse", 1, kAny);
        for (const char* part : {"indices", "values"}) {
            json* p = object_at(*sparse, part, where + " sparse");
            if (p == nullptr) continue;
            const std::string w = where + " sparse " + part;
            index(*p, "bufferView", w, "bufferViews");
            integer(*p, "byteOffset", w, 0, kAny);
            integer(*p, "componentType", w, 5120, 5130);
        }
    }

    /// A bufferView's numbers, and its bytes inside its buffer's declared length.
    void buffer_view(json& v, const std::string& where) {
        index(v, "buffer", where, "buffers");
        integer(v, "byteOffset", where, 0, kAny);
        integer(v, "byteLength", where, 1, kAny);
        integer(v, "byteStride", where, 0, 252);
        integer(v, "target", where, 0, 65535);
        auto buffer = v.find("buffer"), length = v.find("byteLength");
        if (buffer == v.end() || length == v.end()) return;
        const json& b = m_doc["buffers"][buffer->get<size_t>()];
        auto total = b.find("byteLength");
        if (total == b.end() || !total->is_number()) return;
        const double offset = v.value("byteOffset", 0.0), end = offset + length->get<double>();
        if (end > total->get<double>())
            fail(where, "bytes " + json(int64_t(offset)).dump() + ".." + json(int64_t(end)).dump() +
                            " out of range of buffer " + buffer->dump() + " (" + total->dump() + " bytes)");
    }

    /// Every textureInfo (a key ending in "Texture") under a material, extensions included.
    void texture_infos(json& value, const std::string& where) {
        if (!value.is_object()) return;
        for (auto it = value.begin(); it != value.end(); ++it) {
            const std::string& key = it.key();
            const std::string path = where + "." + key;
            const bool texture = key.size() >= 7 && key.compare(key.size() - 7, 7, "Texture") == 0;
            if (texture && it->is_object()) {
                auto idx = it->find("index");
                if (idx != it->end())
                    check_index(*idx, path, "index", "textures", count("textures"));
                integer(*it, "texCoord", path, 0, 255);
            } else if (key != "extras") {
                texture_infos(it.value(), path);
            }
        }
    }

    void animation(json& a, const std::string& where) {
        auto samplers = a.find("samplers");
        const size_t local = samplers != a.end() && samplers->is_array() ? samplers->size() : 0;
        if (auto channels = a.find("channels"); channels != a.end() && channels->is_array())
            for (size_t c = 0; c < channels->size(); ++c) {
                json& ch = (*channels)[c];
                const std::string w = where + " channel " + std::to_string(c);
                if (!ch.is_object()) fail(w, "is not an object");
                if (auto s = ch.find("sampler"); s != ch.end()) check_index(*s, w, "sampler", "samplers", local);
                if (json* target = object_at(ch, "target", w)) index(*target, "node", w + " target", "nodes");
            }
        for (size_t s = 0; s < local; ++s)
            if ((*samplers)[s].is_object())
                for (const char* key : {"input", "output"})
                    index((*samplers)[s], key, where + " sampler " + std::to_string(s), "accessors");
    }

    const std::string& m_file;
    json& m_doc;
    bool m_changed = false;
};

}  // namespace

std::string normalize_document(const std::string& file, const unsigned char* text, size_t size) {
    json doc = json::parse(text, text + size, nullptr, false);
    if (doc.is_discarded() || !doc.is_object()) return {};  // tinygltf reports the parse error
    Normalizer n(file, doc);
    n.run();
    return n.changed() ? doc.dump() : std::string();
}

}  // namespace rtsim::gltf
