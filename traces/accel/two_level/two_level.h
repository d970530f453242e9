#pragma once
// Two-level structures (docs/accel.md, "Two-level structures"): one bottom-level structure
// (BLAS) per mesh geometry in object space, of any registered kind, and a top-level binary BVH (TLAS)
// over the instances' world boxes whose leaves point at instance records (instance_record.h).
//
// Image (kind "two_level"): regions "tlas_nodes" (HwNode, 64 bytes; a leaf slot holds one
// instance: child_ref = instance record index, child_count = 1), "instances" (InstanceRecord,
// 128 bytes, in TLAS leaf order), then for every region R of the BLAS kind a region "blas_R":
// the BLASes' R regions concatenated, each starting on a 64-byte boundary. Params:
// {"blas_kind", "blas": [{"params", "bounds", "first": {R: record}, "count": {R: records}}]}.
#include <memory>
#include <string>
#include <vector>

#include "traces/accel/accel.h"
#include "traces/accel/bvh2/bvh2_stepper.h"
#include "traces/accel/two_level/instance_record.h"

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

class TwoLevelAccel final : public Accel {
public:
    /// Splits the image into its BLASes (each loaded, so validated, by its kind) and validates
    /// the TLAS and the instance records; throws rtsim::Error naming `source` and the record.
    TwoLevelAccel(AccelImage image, const std::string& source);

    std::unique_ptr<Stepper> make_stepper() const override;
    LocalityPartition partition(uint64_t budget_bytes) const override;
    std::vector<OpKind> op_kinds() const override;
    uint32_t max_stack_entries() const override;

    const Bvh2View& tlas() const { return m_tlas; }
    const InstanceRecordView& instances() const { return m_instances; }
    const std::vector<std::unique_ptr<Accel>>& blases() const { return m_blases; }
    /// Locality key of BLAS b's key 0 (TLAS nodes take keys 0..tlas node count - 1).
    uint32_t locality_offset(size_t blas) const { return m_locality_offset[blas]; }

private:
    Bvh2View m_tlas;
    InstanceRecordView m_instances;
    std::vector<std::unique_ptr<Accel>> m_blases;
    std::vector<uint32_t> m_locality_offset;
};

}  // namespace rtsim
