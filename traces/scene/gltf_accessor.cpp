// Bounds-checked access to glTF accessors. tinygltf checks little of the buffer arithmetic, so
// every byte a view can reach is proven to lie inside its bufferView and buffer here, once.
#include <algorithm>
#include <cstring>
#include <limits>
#include <sstream>

#include "traces/scene/gltf_internal.h"

namespace rtsim::gltf {

void Source::fail(const std::string& what) const { throw Error(file + ": " + what); }

std::string element(const char* kind, size_t index, const std::string& name) {
    std::string s = std::string(kind) + " " + std::to_string(index);
    if (!name.empty()) s += " '" + name + "'";
    return s;
}

double value_number(const tinygltf::Value& object, const char* key, double fallback) {
    if (!object.IsObject() || !object.Has(key)) return fallback;
    const tinygltf::Value& v = object.Get(key);
    return v.IsNumber() ? v.GetNumberAsDouble() : fallback;
}

int as_index(double number) {
    if (!(number >= 0.0 && number < 2147483647.0)) return -1;  // also rejects NaN
    int i = int(number);
    return double(i) == number ? i : -1;
}

namespace {

int component_size(int type) {
    switch (type) {
        case TINYGLTF_COMPONENT_TYPE_BYTE:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
        case TINYGLTF_COMPONENT_TYPE_SHORT:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
        case TINYGLTF_COMPONENT_TYPE_INT:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
        case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
        case TINYGLTF_COMPONENT_TYPE_DOUBLE: return 8;
        default: return 0;
    }
}

int component_count(int type) {
    switch (type) {
        case TINYGLTF_TYPE_SCALAR: return 1;
        case TINYGLTF_TYPE_VEC2: return 2;
        case TINYGLTF_TYPE_VEC3: return 3;
        case TINYGLTF_TYPE_VEC4: return 4;
        case TINYGLTF_TYPE_MAT2: return 4;
        case TINYGLTF_TYPE_MAT3: return 9;
        case TINYGLTF_TYPE_MAT4: return 16;
        default: return 0;
    }
}

template <typename T>
T load(const unsigned char* p) {
    T v;
    std::memcpy(&v, p, sizeof(T));
    return v;
}

}  // namespace

AccessorView view_accessor(const Source& src, int index, const std::string& where) {
    const tinygltf::Model& m = *src.model;
    if (index < 0 || size_t(index) >= m.accessors.size())
        src.fail(where + ": accessor index " + std::to_string(index) + " out of range (" +
                 std::to_string(m.accessors.size()) + " accessors)");
    const tinygltf::Accessor& acc = m.accessors[size_t(index)];
    std::string name = where + ": " + element("accessor", size_t(index), acc.name);
    if (acc.sparse.isSparse) src.fail(name + ": sparse accessors are not supported");
    if (acc.bufferView < 0 || size_t(acc.bufferView) >= m.bufferViews.size())
        src.fail(name + ": bufferView index " + std::to_string(acc.bufferView) + " out of range (" +
                 std::to_string(m.bufferViews.size()) + " bufferViews)");
    const tinygltf::BufferView& bv = m.bufferViews[size_t(acc.bufferView)];
    std::string bv_name = name + ": " + element("bufferView", size_t(acc.bufferView), bv.name);
    if (bv.buffer < 0 || size_t(bv.buffer) >= m.buffers.size())
        src.fail(bv_name + ": buffer index " + std::to_string(bv.buffer) + " out of range");
    const tinygltf::Buffer& buf = m.buffers[size_t(bv.buffer)];

    // The bufferView must lie inside its buffer.
    if (bv.byteOffset > buf.data.size() || bv.byteLength > buf.data.size() - bv.byteOffset) {
        std::ostringstream os;
        os << bv_name << ": bytes [" << bv.byteOffset << ", " << bv.byteOffset + bv.byteLength
           << ") out of range of buffer " << bv.buffer << " (" << buf.data.size() << " bytes)";
        src.fail(os.str());
    }
    AccessorView view;
    view.component_type = acc.componentType;
    view.components = component_count(acc.type);
    view.normalized = acc.normalized;
    view.count = acc.count;
    size_t elem = size_t(component_size(acc.componentType)) * size_t(view.components);
    if (elem == 0) src.fail(name + ": unsupported componentType/type");
    view.stride = bv.byteStride ? bv.byteStride : elem;
    if (view.stride < elem)
        src.fail(bv_name + ": byteStride " + std::to_string(bv.byteStride) +
                 " smaller than the element size " + std::to_string(elem));

    // The accessor's last element must end inside the bufferView (overflow-safe arithmetic).
    if (acc.count > 0) {
        size_t limit = bv.byteLength;
        bool bad = acc.byteOffset > limit || elem > limit - acc.byteOffset ||
                   (acc.count - 1) > (limit - acc.byteOffset - elem) / view.stride;
        if (bad) {
            std::ostringstream os;
            os << name << ": byteOffset " << acc.byteOffset << " + stride " << view.stride << " x count "
               << acc.count << " out of range of " << element("bufferView", size_t(acc.bufferView))
               << " (" << bv.byteLength << " bytes)";
            src.fail(os.str());
        }
    }
    view.data = buf.data.data() + bv.byteOffset + acc.byteOffset;
    return view;
}

float AccessorView::component(size_t i, int c) const {
    const unsigned char* p = data + i * stride;
    switch (component_type) {
        case TINYGLTF_COMPONENT_TYPE_FLOAT: return load<float>(p + 4 * c);
        case TINYGLTF_COMPONENT_TYPE_DOUBLE: return float(load<double>(p + 8 * c));
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
            float v = float(load<uint8_t>(p + c));
            return normalized ? v / 255.0f : v;
        }
        case TINYGLTF_COMPONENT_TYPE_BYTE: {
            float v = float(load<int8_t>(p + c));
            return normalized ? std::max(v / 127.0f, -1.0f) : v;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            float v = float(load<uint16_t>(p + 2 * c));
            return normalized ? v / 65535.0f : v;
        }
        case TINYGLTF_COMPONENT_TYPE_SHORT: {
            float v = float(load<int16_t>(p + 2 * c));
            return normalized ? std::max(v / 32767.0f, -1.0f) : v;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return float(load<uint32_t>(p + 4 * c));
        case TINYGLTF_COMPONENT_TYPE_INT: return float(load<int32_t>(p + 4 * c));
        default: return 0.0f;
    }
}

uint32_t AccessorView::index(size_t i) const {
    const unsigned char* p = data + i * stride;
    switch (component_type) {
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return load<uint8_t>(p);
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return load<uint16_t>(p);
        default: return load<uint32_t>(p);
    }
}

}  // namespace rtsim::gltf
