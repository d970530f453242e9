// The two-level Accel (two_level.h): splits its image into BLAS images (each loaded, so
// validated, by its own kind), validates the TLAS and the instance records, and composes the
// BLASes' locality partitions under the TLAS's.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "traces/accel/bvh2/bvh2.h"
#include "traces/accel/two_level/two_level.h"
#include "traces/accel/two_level/two_level_packet.h"
#include "traces/accel/two_level/two_level_stepper.h"
#include "traces/common/error.h"

namespace rtsim {

using nlohmann::json;

namespace {

const json& field(const json& obj, const char* key, const std::string& where) {
    require(obj.is_object() && obj.contains(key), where + ": '" + key + "' is missing");
    return obj.at(key);
}

Aabb parse_bounds(const json& b, const std::string& where) {
    Aabb box;
    for (int side = 0; side < 2; ++side) {
        const json& v = field(b, side ? "hi" : "lo", where);
        require(v.is_array() && v.size() == 3, where + ": bounds must hold 3 numbers per side");
        for (int a = 0; a < 3; ++a) {
            require(v[a].is_number(), where + ": bounds must hold numbers");
            (side ? box.hi : box.lo)[a] = v[a].get<float>();
        }
    }
    return box;
}

/// BLAS `b`'s image: its slices of the image's "blas_*" regions, at their addresses there.
AccelImage blas_image(const AccelImage& image, const std::string& kind, const json& entry, const std::string& where) {
    AccelImage sub;
    sub.kind = kind;
    sub.params = field(entry, "params", where);
    sub.bounds = parse_bounds(field(entry, "bounds", where), where);
    const json& first = field(entry, "first", where);
    const json& count = field(entry, "count", where);
    for (const Region& r : image.regions) {
        if (r.name.rfind("blas_", 0) != 0) continue;
        const std::string name = r.name.substr(5);
        const json& f = field(first, name.c_str(), where + ".first");
        const json& c = field(count, name.c_str(), where + ".count");
        require(f.is_number_unsigned() && c.is_number_unsigned(), where + ": region '" + name + "' slice is not unsigned");
        const uint64_t f0 = f.get<uint64_t>(), n = c.get<uint64_t>();
        require(f0 <= r.count && n <= r.count - f0, where + ": region '" + name + "' slice [" + std::to_string(f0) +
                                                        ", +" + std::to_string(n) + ") is outside " + r.name);
        Region& out = sub.add_region(name, r.kind, r.record_bytes, 0, r.layout);
        out.count = n;
        out.base = r.address(f0);
        out.bytes.resize(n * r.record_bytes, false);
        if (n) std::memcpy(out.bytes.data(), r.bytes.data() + f0 * r.record_bytes, n * r.record_bytes);
    }
    return sub;
}

/// Locality keys of a structure: its node or cell records.
uint32_t locality_key_count(const AccelImage& image) {
    uint64_t keys = 1;
    for (const Region& r : image.regions)
        if (r.kind == DataKind::node || r.kind == DataKind::cell) keys = std::max(keys, r.count);
    return uint32_t(keys);
}

bool finite_rows(const float m[12]) {
    return std::all_of(m, m + 12, [](float x) { return std::isfinite(x); });
}

}  // namespace

TwoLevelAccel::TwoLevelAccel(AccelImage image, const std::string& source) : Accel(std::move(image)) {
    const std::string where = source + ": two-level structure";
    require(m_image.kind == "two_level", where + ": kind is '" + m_image.kind + "'");
    const Region& nodes = m_image.region("tlas_nodes");
    const Region& records = m_image.region("instances");
    require(nodes.record_bytes == sizeof(HwNode) && records.record_bytes == sizeof(InstanceRecord),
            where + ": 'tlas_nodes' or 'instances' has the wrong record size");
    const json& params = m_image.params;
    const json& kind = field(params, "blas_kind", where + " params");
    const json& list = field(params, "blas", where + " params");
    require(kind.is_string() && list.is_array(), where + ": params 'blas_kind' or 'blas' has the wrong type");
    uint32_t offset = uint32_t(nodes.count);  // BLAS keys follow every frame's TLAS nodes
    for (size_t b = 0; b < list.size(); ++b) {
        const std::string at = where + " BLAS " + std::to_string(b);
        m_blases.push_back(load_accel(blas_image(m_image, kind.get<std::string>(), list[b], at), at));
        m_locality_offset.push_back(offset);
        offset += locality_key_count(m_blases.back()->image());
    }
    // Without "frames" the image is one frame: the whole regions.
    if (!params.contains("frames")) {
        add_frame({{"tlas_first", uint64_t(0)}, {"tlas_count", nodes.count}, {"instances_first", uint64_t(0)},
                   {"instances_count", records.count}},
                  where);
        return;
    }
    const json& frames = params.at("frames");
    require(frames.is_array() && !frames.empty(), where + ": params 'frames' must be a non-empty array");
    for (size_t f = 0; f < frames.size(); ++f) add_frame(frames[f], where + " frame " + std::to_string(f));
}

void TwoLevelAccel::add_frame(const json& slice, const std::string& where) {
    const Region& nodes = m_image.region("tlas_nodes");
    const Region& records = m_image.region("instances");
    auto range = [&](const char* first_key, const char* count_key, const Region& r) {
        const json& f = field(slice, first_key, where), &c = field(slice, count_key, where);
        require(f.is_number_unsigned() && c.is_number_unsigned(),
                where + ": '" + first_key + "' or '" + count_key + "' is not an unsigned integer");
        const uint64_t first = f.get<uint64_t>(), count = c.get<uint64_t>();
        require(first <= r.count && count <= r.count - first, where + ": slice [" + std::to_string(first) + ", +" +
                                                                  std::to_string(count) + ") is outside " + r.name);
        return std::pair<uint64_t, uint64_t>(first, count);
    };
    const auto [node_first, node_count] = range("tlas_first", "tlas_count", nodes);
    const auto [record_first, record_count] = range("instances_first", "instances_count", records);
    Frame fr;
    fr.tlas.nodes = nodes.records<HwNode>() + node_first;
    fr.tlas.node_count = node_count;
    fr.tlas.node_base = nodes.address(node_first);
    fr.tlas.triangle_count = record_count;  // a TLAS leaf's "triangles" are instance records
    fr.tlas.tri_at.base = records.address(record_first);
    fr.instances = {records.records<InstanceRecord>() + record_first, record_count, records.address(record_first)};
    fr.key_base = uint32_t(node_first);
    validate_bvh2(fr.tlas, where + " TLAS");
    for (uint64_t i = 0; i < node_count; ++i)
        for (int c = 0; c < 2; ++c) {
            const uint32_t n = fr.tlas.nodes[i].child_count[c];
            require(n <= 1 || n == kEmptyChild, where + ": TLAS node " + std::to_string(i) + " child " +
                                                    std::to_string(c) + " is a leaf of " + std::to_string(n) +
                                                    " instances (one per leaf)");
        }
    for (uint64_t i = 0; i < record_count; ++i) {
        const InstanceRecord& r = fr.instances.records[i];
        const std::string at = where + ": instance record " + std::to_string(i);
        require(r.blas < m_blases.size(), at + " names BLAS " + std::to_string(r.blas) + " of " +
                                              std::to_string(m_blases.size()));
        require(finite_rows(r.world_to_object) && finite_rows(r.object_to_world), at + " has a non-finite transform");
        require(r.prim_base < (1u << 31), at + " has a primitive base beyond 2^31");
    }
    m_frames.push_back(fr);
}

void TwoLevelAccel::bind_frame(uint32_t f) {
    Accel::bind_frame(f);  // checks the range
    m_frame = f;
}

std::unique_ptr<Stepper> TwoLevelAccel::make_stepper(const StepOptions& options) const {
    return std::make_unique<TwoLevelStepper>(*this, options);
}

std::unique_ptr<PacketStepper> TwoLevelAccel::make_packet_stepper(const StepOptions& options) const {
    if (!capabilities().packet_kernel) return nullptr;
    return std::make_unique<TwoLevelPacketStepper>(*this, options);
}

LocalityPartition TwoLevelAccel::partition(uint64_t budget_bytes) const {
    require(budget_bytes >= sizeof(HwNode), "treelet budget must be at least one node (64 bytes)");
    // Each frame's TLAS partitioned on its own, its keys at the frame's place in "tlas_nodes".
    LocalityPartition out;
    out.budget_bytes = budget_bytes;
    for (size_t f = 0; f < m_frames.size(); ++f) {
        const Frame& fr = m_frames[f];
        const LocalityPartition p =
            partition_tree(bvh2_locality_tree(fr.tlas.nodes, fr.tlas.node_count), budget_bytes);
        const uint32_t group_base = uint32_t(out.treelets.size());
        if (f == 0) out.root_group = group_base + p.root_group;
        out.group_of.resize(fr.key_base + fr.tlas.node_count, group_base + p.root_group);
        for (size_t k = 0; k < p.group_of.size() && k < fr.tlas.node_count; ++k)
            out.group_of[fr.key_base + k] = group_base + p.group_of[k];
        for (TreeletInfo t : p.treelets) {
            t.root += fr.key_base;
            out.treelets.push_back(t);
        }
    }
    for (size_t b = 0; b < m_blases.size(); ++b) {
        const LocalityPartition p = m_blases[b]->partition(budget_bytes);
        const uint32_t group_base = uint32_t(out.treelets.size());
        const uint32_t keys = locality_key_count(m_blases[b]->image());
        out.group_of.resize(m_locality_offset[b] + keys, group_base + p.root_group);
        for (size_t k = 0; k < p.group_of.size() && k < keys; ++k)
            out.group_of[m_locality_offset[b] + k] = group_base + p.group_of[k];
        for (TreeletInfo t : p.treelets) {
            t.root += m_locality_offset[b];
            t.depth += 1;
            out.treelets.push_back(t);
        }
    }
    return out;
}

std::vector<OpKind> TwoLevelAccel::op_kinds() const {
    std::vector<OpKind> kinds{OpKind::box, OpKind::transform};
    for (const auto& b : m_blases)
        for (OpKind k : b->op_kinds())
            if (std::find(kinds.begin(), kinds.end(), k) == kinds.end()) kinds.push_back(k);
    return kinds;
}

uint32_t TwoLevelAccel::max_stack_entries() const {
    uint32_t deepest = 0;
    for (const auto& b : m_blases) deepest = std::max(deepest, b->max_stack_entries());
    return kTraversalStackSize + deepest;
}

AccelCapabilities TwoLevelAccel::capabilities() const {
    return accel_capabilities(kind(), m_image.params.value("blas_kind", "bvh2"));
}

}  // namespace rtsim
