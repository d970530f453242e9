#pragma once
// The binary BVH with oriented boxes behind the acceleration-structure seam (docs/accel.md,
// "obvh2"; layout in docs/bvh_layout.md, "HwObbNode"). A node may store its two child boxes in a
// rotated frame instead of the world's axes: one rotation per node, chosen from a fixed table the
// traversal unit holds, as AMD's RDNA 4 BVH8 nodes select "a matrix for transforming the ray
// before performing intersection tests" by a 7-bit index (0x7F: none; Mesa's GFX12 BVH notes) and
// AMD's patent US 12,079,919 quantises the rotation as an axis and an amount. The traversal unit
// rotates the ray into the node's frame (an `obb` operation) and tests the child boxes there as
// axis-aligned ones: the parameter t is the same in both frames, so entry distances, culling
// and the closest-hit order are unchanged.
//
// Built from any binary build tree: the tree's topology is kept and each node's orientation is
// fitted afterwards (Vitsas et al. 2023, "Parallel transformation of bounding volume hierarchies
// into oriented bounding box trees", do the same with free orientations): for every table
// rotation the subtrees' boxes in that frame are computed bottom-up (a box of a union is the
// union of the boxes, so exactly), and a node takes the rotation whose two child boxes have the
// least summed surface area (the SAH's hit probability of each child) if that cuts the
// axis-aligned children's area by at least `min_gain`.
//
// Rounding: the boxes bound the vertices rotated in float and the ray is rotated in float; the
// stepper widens an oriented node's boxes by a bound on both errors (obb_pad), so no box a ray
// truly crosses is missed (docs/intersection.md, "Oriented boxes").
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "traces/accel/accel.h"
#include "traces/accel/bvh2/bvh2_stepper.h"
#include "traces/accel/obvh/obvh_rotate.h"
#include "traces/bvh/build_tree.h"
#include "traces/bvh/hw_layout.h"

namespace rtsim {

struct Scene;

/// HwObbNode::child_count of an unused child slot (only in the root of a one-leaf tree).
constexpr uint16_t kObbEmptyChild = 0xFFFF;

struct alignas(64) HwObbNode {  // 64 bytes, one line per fetch, as HwNode
    /// Both child boxes in the node's frame, laid out as HwNode's: bounds[axis][min/max][child].
    float bounds[3][2][2];      //  0
    uint32_t child_ref[2];      // 48: interior child: node index; leaf: first triangle index
    uint16_t child_count[2];    // 56: 0: interior child; kObbEmptyChild: no child; else leaf size
    uint8_t rotation;           // 60: index into params.rotations; kNoRotation: the world's axes
    uint8_t pad[3];             // 61: zero
};
static_assert(sizeof(HwObbNode) == 64, "HwObbNode must be one 64-byte line");
inline RecordLayout layout_of(const HwObbNode*) {
    return {RTSIM_FIELD(HwObbNode, bounds), RTSIM_FIELD(HwObbNode, child_ref), RTSIM_FIELD(HwObbNode, child_count),
            RTSIM_FIELD(HwObbNode, rotation), RTSIM_FIELD(HwObbNode, pad)};
}

/// A row-major 3x3 rotation: frame coordinates = m * world coordinates.
using Rotation = std::array<float, 9>;

/// The oriented BVH's settings beyond its tree builder's.
struct ObbConfig {
    /// Rotations by k x 90 / angle_steps degrees (k = 1 .. steps - 1)
    /// about x, y and z (a quarter turn maps a box to a box, so larger angles repeat these). It
    /// brings onto a box axis only directions lying in a coordinate plane: a strand along
    /// (1, 1, 1) stays 35 degrees off every axis of every frame.
    uint32_t angle_steps = 32;
    /// Tilted frames beside them: a turn about z by i x 180 / turn_steps degrees, then a tilt
    /// about x by j x 180 / tilt_steps degrees (j >= 1, but not a quarter tilt, which gives a turn
    /// about z again; tilt_steps = 1: none), whose frames bring any direction within a few
    /// degrees of a box axis (docs/accel.md, "obvh2").
    uint32_t turn_steps = 14, tilt_steps = 1;
    /// A node is oriented only if its children's summed surface area drops by this fraction.
    float min_gain = 0.1f;
    /// A refit keeps each node's rotation (its children boxed in that frame, or on the world's
    /// axes where those are smaller now) instead of fitting every rotation again: fewer node
    /// frames for the build unit, rotations that age as the geometry moves.
    bool refit_keeps_rotations = false;

    template <class V>
    void visit(V& v) {
        v.field("obb_angle_steps", angle_steps, "steps", "Rotations about one axis: k x 90/steps degrees about x, y, z (3 x (steps - 1) of them; 1: none)", 1, 43);
        v.field("obb_turn_steps", turn_steps, "steps", "Tilted frames: turns about z by i x 180/steps degrees", 1, 126);
        v.field("obb_tilt_steps", tilt_steps, "steps", "Tilted frames: tilts about x by j x 180/steps degrees after each turn, j >= 1 but not a quarter tilt (turns x (steps - 1) of them, one fewer tilt for even steps; 1: none); with the one-axis ones at most 126", 1, 126);
        v.flag("obb_refit_keeps_rotations", refit_keeps_rotations, "A refit keeps each node's rotation, boxing its children in that frame (every subtree in each oriented ancestor's frame), instead of fitting every rotation again");
        v.field("obb_min_gain", min_gain, "fraction", "Orient a node only if its children's summed surface area drops by this fraction", 0, 1);
    }
};

/// The rotation table of `obb`: the 3 x (angle_steps - 1) rotations about one axis, then the
/// tilted frames (turn_steps x (tilt_steps - 1), less a quarter tilt's); index kNoRotation is none. Throws naming the
/// settings when the table is empty or would not fit the node's 7-bit index.
std::vector<Rotation> obb_rotation_table(const ObbConfig& obb);

/// The image of an oriented BVH from a binary build tree: regions "nodes" (HwObbNode) and
/// "triangles" (HwTriangle, in leaf order), params.rotations the table, stats the fit's
/// (`fit_node_frames`: the node boxes it computed, one per node and frame). With `kept` (a
/// refitted tree's previous rotations, one per node) each node keeps its rotation instead of
/// the fit trying the table.
AccelImage obvh2_image(const BuildTree& tree, const Scene& scene, const BuildConfig& config, const ObbConfig& obb,
                       const std::string& builder, unsigned threads, const std::vector<uint8_t>* kept = nullptr);
/// The rotation per node of an obvh2 image (its "nodes" region), for TreeReuse::rotations.
std::vector<uint8_t> obvh2_rotations(const AccelImage& image);

/// The host's view of an oriented image: nodes as HwNode (boxes in each node's frame), the
/// rotation of each and the table, read by the binary BVH's stepper (bvh2_stepper.h).
class ObvhAccel final : public Accel {
public:
    ObvhAccel(AccelImage image, const std::string& source);

    std::unique_ptr<Stepper> make_stepper(const StepOptions& options = {}) const override;
    /// Packets as the binary BVH's (bvh2_packet.h), each ray rotated into an oriented node's frame.
    std::unique_ptr<PacketStepper> make_packet_stepper(const StepOptions& options = {}) const override;
    void trace_packet(const Ray* rays, const TraversalMode* modes, uint32_t n, Hit* hits, WorkCounts* work,
                      PacketCounts* counts, float split_below, const StepOptions& options = {}) const override;
    LocalityPartition partition(uint64_t budget_bytes) const override;
    std::vector<OpKind> op_kinds() const override;
    uint32_t max_stack_entries() const override { return kTraversalStackSize; }
    const Bvh2View& view() const { return m_view; }

private:
    std::vector<HwNode> m_nodes;
    std::vector<uint8_t> m_rotations;
    std::vector<float> m_table;
    Bvh2View m_view;
};

}  // namespace rtsim
