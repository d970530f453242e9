#pragma once
// Two-level structures (docs/accel.md, "Two-level structures"): one bottom-level structure
// (BLAS) per mesh geometry in object space, of any registered kind, and a top-level binary BVH (TLAS)
// over the instances' world boxes whose leaves point at instance records (instance_record.h).
//
// Image (kind "two_level"): regions "tlas_nodes" (HwNode, 64 bytes; a leaf slot holds one
// instance: child_ref = instance record index, child_count = 1), "instances" (InstanceRecord,
// 128 bytes, in TLAS leaf order), then for every region R of the BLAS kind a region "blas_R":
// the BLASes' R regions concatenated, each starting on a 64-byte boundary. Params:
// {"blas_kind", "blas": [{"params", "bounds", "first": {R: record}, "count": {R: records}}]}, and
// for animated frames "frames": [{"tlas_first", "tlas_count", "instances_first",
// "instances_count"}], each frame's TLAS (node 0 its root, leaves naming records of its own
// slice) and records back to back in "tlas_nodes" and "instances" (build_two_level_frames).
#include <memory>
#include <string>
#include <vector>

#include "traces/accel/accel.h"
#include "traces/accel/bvh2/bvh2_stepper.h"
#include "traces/accel/two_level/frame_policy.h"
#include "traces/accel/two_level/instance_record.h"
#include "traces/scene/mesh_animation.h"

namespace rtsim {

/// For each mesh, the first mesh of the same geometry: vertices equal bit for bit and the same
/// alpha test per triangle (materials may differ: shading looks them up by primitive id). Meshes
/// of one class share a BLAS.
std::vector<uint32_t> geometry_classes(const Scene& scene);
/// True when some geometry is placed more than once (shared meshes, EXT_mesh_gpu_instancing, or
/// glTF meshes sharing accessors): the scenes the tracer builds two-level by default.
bool shares_geometry(const Scene& scene);

/// Builds the two-level image of a scene's instances: a BLAS of kind `options.kind` (and its
/// builder) per mesh that some instance uses, and the TLAS. Needs meshes and instances only
/// (the scene need not be flattened).
AccelImage build_two_level(const Scene& scene, const AccelOptions& options);

/// Wall times of a multi-frame build (not in the image: images are deterministic).
struct TwoLevelTiming {
    double blas_ms = 0.0;         ///< every BLAS, built once
    std::vector<double> tlas_ms;  ///< each frame's TLAS and instance records
    std::vector<double> blas_frame_ms;  ///< frames 1..N-1: the deforming meshes' BLASes
};

/// Animated frames (docs/accel.md, "Frames"): the BLASes built once, then a TLAS and instance
/// records per frame from poses[f][i], instance i's object-to-world in frame f. The frames'
/// TLASes lie back to back in "tlas_nodes" and their records in "instances" (each frame at its
/// own addresses, like a driver writing a new top-level buffer); params "frames" lists each
/// frame's slices [{"tlas_first", "tlas_count", "instances_first", "instances_count"}] when
/// there is more than one. One pose is exactly build_two_level().
/// Geometry that deforms over frames (docs/accel.md, "Moving scenes") and the policy its
/// structures follow: each deforming mesh gets a BLAS per frame from animation->pose() (frames
/// after the first appended to the BLAS regions), built or refitted by `policy`, which the
/// TLAS follows too. Each frame's slice then carries "build": {"blas": [{"mesh", "blas",
/// "action", "tree_nodes", "sah_cost", "sah_ratio", "triangles", "bytes"}], "tlas": {...}}.
struct FrameGeometry {
    const MeshAnimation* animation = nullptr;  ///< null: only instances move
    FramePolicyOptions policy;
};
AccelImage build_two_level_frames(const Scene& scene, const AccelOptions& options,
                                  const std::vector<std::vector<glm::dmat4>>& poses, TwoLevelTiming* timing,
                                  const FrameGeometry& geometry = {});

class TwoLevelAccel final : public Accel {
public:
    /// Splits the image into its BLASes (each loaded, so validated, by its kind) and validates
    /// the TLAS and the instance records; throws rtsim::Error naming `source` and the record.
    TwoLevelAccel(AccelImage image, const std::string& source);

    std::unique_ptr<Stepper> make_stepper(const StepOptions& options = {}) const override;
    /// Packets walk the TLAS together and each instance's BLAS as a packet of the rays that
    /// entered it (two_level_packet.h), where the BLAS kind has a packet kernel.
    std::unique_ptr<PacketStepper> make_packet_stepper(const StepOptions& options = {}) const override;
    LocalityPartition partition(uint64_t budget_bytes) const override;
    std::vector<OpKind> op_kinds() const override;
    uint32_t max_stack_entries() const override;
    /// The BLAS kind's, the stack entry the larger of the TLAS's 8 bytes and the BLAS kind's (the
    /// stack holds both); restart trails per level, the BLASes' reduced-precision walks
    /// (two_level_stepper.h) and compressed leaves (each BLAS built with its own leaf blocks, a
    /// slice of "blas_leaf_blocks"); the BLAS kind's packet kernel (two_level_packet.h).
    AccelCapabilities capabilities() const override;

    uint32_t frame_count() const override { return uint32_t(m_frames.size()); }
    void bind_frame(uint32_t f) override;

    /// The bound frame's TLAS and instance records (frame 0 until bind_frame()).
    const Bvh2View& tlas() const { return m_frames[m_frame].tlas; }
    const InstanceRecordView& instances() const { return m_frames[m_frame].instances; }
    /// Locality key of the bound frame's TLAS node 0 (TLAS node keys are their index in the
    /// "tlas_nodes" region, every frame's nodes included).
    uint32_t tlas_key_base() const { return m_frames[m_frame].key_base; }
    const std::vector<std::unique_ptr<Accel>>& blases() const { return m_blases; }
    /// Locality key of BLAS b's key 0 (TLAS nodes take keys 0..tlas node count - 1).
    uint32_t locality_offset(size_t blas) const { return m_locality_offset[blas]; }

private:
    /// One frame's slice of the "tlas_nodes" and "instances" regions (two_level.h, frames).
    struct Frame {
        Bvh2View tlas;
        InstanceRecordView instances;
        uint32_t key_base = 0;
    };
    void add_frame(const nlohmann::json& slice, const std::string& where);

    std::vector<Frame> m_frames;
    uint32_t m_frame = 0;
    std::vector<std::unique_ptr<Accel>> m_blases;
    std::vector<uint32_t> m_locality_offset;
};

}  // namespace rtsim
