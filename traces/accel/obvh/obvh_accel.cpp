// The oriented BVH's Accel: the image's HwObbNodes opened as the binary BVH's view (obvh.h).
#include <cmath>
#include <string>

#include "traces/accel/bvh2/bvh2.h"
#include "traces/accel/leaf_blocks.h"
#include "traces/accel/obvh/obvh.h"
#include "traces/common/error.h"

namespace rtsim {

ObvhAccel::ObvhAccel(AccelImage image, const std::string& source) : Accel(std::move(image)) {
    const Region& nodes = m_image.region("nodes");
    const Region& tris = triangle_region(m_image);
    require(nodes.record_bytes == sizeof(HwObbNode) && triangle_records_ok(tris),
            source + ": obvh2 regions must hold 64-byte nodes and 48-byte triangles");
    // The rotation table: the unit's constant matrices, as the build wrote them.
    const nlohmann::json& table = m_image.params.value("rotations", nlohmann::json());
    require(table.is_array() && table.size() < kNoRotation,
            source + ": obvh2 params.rotations must be an array of at most 126 rotations");
    for (size_t r = 0; r < table.size(); ++r) {
        require(table[r].is_array() && table[r].size() == 9,
                source + ": obvh2 rotation " + std::to_string(r) + " is not a 3x3 matrix (9 numbers)");
        for (const nlohmann::json& x : table[r]) {
            require(x.is_number() && std::fabs(x.get<double>()) <= 1.0,
                    source + ": obvh2 rotation " + std::to_string(r) + " has an entry that is not a number in [-1, 1]");
            m_table.push_back(x.get<float>());
        }
    }
    const HwObbNode* in = nodes.records<HwObbNode>();
    m_nodes.resize(nodes.count);
    m_rotations.resize(nodes.count);
    for (uint64_t i = 0; i < nodes.count; ++i) {
        const uint8_t r = in[i].rotation;
        require(r == kNoRotation || r < table.size(),
                source + ": obvh2 node " + std::to_string(i) + " names rotation " + std::to_string(r) + " of " +
                    std::to_string(table.size()));
        m_rotations[i] = r;
        HwNode& n = m_nodes[i];
        std::copy(&in[i].bounds[0][0][0], &in[i].bounds[0][0][0] + 12, &n.bounds[0][0][0]);
        for (int c = 0; c < 2; ++c) {
            n.child_ref[c] = in[i].child_ref[c];
            n.child_count[c] = in[i].child_count[c] == kObbEmptyChild ? kEmptyChild : in[i].child_count[c];
        }
    }
    m_view.nodes = m_nodes.data();
    m_view.node_count = m_nodes.size();
    m_view.node_base = nodes.base;
    m_triangles = TriangleStore::open(m_image, source);
    m_view.triangles = m_triangles.triangles();
    m_view.triangle_count = m_triangles.count();
    m_view.tri_at = m_triangles.addressing();
    m_view.curved = has_curved();
    m_view.rotations = m_rotations.data();
    m_view.rotation_table = m_table.data();
    // Every vertex lies in the scene's bounds, so within their farthest corner's distance.
    const Aabb& b = m_image.bounds;
    double r2 = 0;
    for (int a = 0; a < 3; ++a) {
        const double m = std::max(std::fabs(double(b.lo[a])), std::fabs(double(b.hi[a])));
        r2 += std::isfinite(m) ? m * m : 0.0;
    }
    m_view.scene_radius = float(std::sqrt(r2) * (1.0 + 0x1p-20));
    validate_bvh2(m_view, source);
}

std::unique_ptr<Stepper> ObvhAccel::make_stepper(const StepOptions& options) const {
    // The binary BVH's stepper: a restart trail's revisit of an oriented node, and the
    // reduced-precision walk's steps at one, rotate the ray as its own steps do.
    return std::make_unique<Bvh2Stepper>(m_view, options.short_stack_entries, options.box_precision_bits,
                                         options.anyhit_order);
}

std::unique_ptr<PacketStepper> ObvhAccel::make_packet_stepper(const StepOptions& options) const {
    return make_bvh2_packet_stepper(m_view, options.anyhit_order);
}

void ObvhAccel::trace_packet(const Ray* rays, const TraversalMode* modes, uint32_t n, Hit* hits, WorkCounts* work,
                             PacketCounts* counts, float split_below, const StepOptions& options) const {
    trace_packet_bvh2(m_view, rays, modes, n, hits, work, counts, split_below, options.anyhit_order);
}

LocalityPartition ObvhAccel::partition(uint64_t budget_bytes) const {
    require(budget_bytes >= sizeof(HwObbNode), "treelet budget must be at least one node (64 bytes)");
    // A box's area is the same in every frame, so the binary BVH's locality tree serves.
    return partition_tree(bvh2_locality_tree(m_view.nodes, m_view.node_count), budget_bytes);
}

std::vector<OpKind> ObvhAccel::op_kinds() const {
    return with_record_kinds({OpKind::box, OpKind::obb, OpKind::triangle});
}

}  // namespace rtsim
