#pragma once
// One seam for every acceleration structure (docs/accel.md, docs/architecture.md):
//
//   builder:  Scene -> AccelImage     (regions of documented layouts at addresses; in the trace)
//   Accel:    AccelImage -> steppers, the fused reference loop, the locality partition
//
// The reference tracer, the model's traversal units, the analytic level and the ray buffer see
// structures only through Accel and Stepper. Structures register by name in registry.cpp;
// adding one touches its own folder and one line there.
#include <memory>
#include <string>
#include <vector>

#include "traces/accel/accel_image.h"
#include "traces/accel/capabilities.h"
#include "traces/accel/leaf_blocks.h"
#include "traces/accel/locality.h"
#include "traces/accel/packet_stepper.h"
#include "traces/accel/step_options.h"
#include "traces/accel/stepper.h"
#include "traces/bvh/config.h"

namespace rtsim {

struct Scene;
struct BuildTree;

/// A build's binary tree kept or reused across frames of moving geometry (docs/accel.md,
/// "Moving scenes"; traces/bvh/refit.h).
struct TreeReuse {
    /// When set, no builder runs: the binary tree is this one refitted to the scene's triangles
    /// (kinds whose capabilities() offer refit; others refuse).
    std::shared_ptr<const BuildTree> refit_from;
    /// The binary tree the build made or refitted (the next frame's topology); null for kinds
    /// built without one.
    std::shared_ptr<const BuildTree> built;
    /// An oriented kind's rotation per node of the image it built (obvh2, in its node order,
    /// which a refit keeps): what a refit that keeps the rotations boxes in; null for others.
    std::shared_ptr<const std::vector<uint8_t>> rotations;
    /// The SAH cost of the image built, when the kind's boxes are not the binary tree's
    /// (oriented boxes, each as its parent holds it): what the frame policy weighs; 0 for others.
    double image_sah_cost = 0.0;
};

/// Bytes of a BVH's traversal stack entry in hardware: a node reference and its entry distance.
constexpr uint32_t kBvhStackEntryBytes = 8;

/// Contract: an Accel owns a validated image. make_stepper() steppers and trace() agree on every
/// ray (hits bit for bit, work counts exactly); both read only the image.
class Accel {
public:
    explicit Accel(AccelImage image) : m_image(std::move(image)) {}
    virtual ~Accel() = default;
    Accel(const Accel&) = delete;
    Accel& operator=(const Accel&) = delete;

    const AccelImage& image() const { return m_image; }
    const std::string& kind() const { return m_image.kind; }

    /// A stepper walking with `options` (step_options.h); an option the structure's capabilities
    /// do not offer is ignored (the run's resolution step never sets one).
    virtual std::unique_ptr<Stepper> make_stepper(const StepOptions& options = {}) const = 0;
    /// The reference loop: the stepper's steps, fused for speed where a kind provides one and
    /// `options` let it (StepOptions::fused_loop_walks_alike); the default drives a stepper.
    virtual Hit trace(const Ray& ray, TraversalMode mode, WorkCounts* work = nullptr,
                      const StepOptions& options = {}) const;
    /// A packet stepper (rays sharing one traversal stack, packet_stepper.h) walking with
    /// `options` (the rays' mailboxes; the others a packet unit never sets), or null where the
    /// kind has no packet kernel (capabilities().packet_kernel false).
    virtual std::unique_ptr<PacketStepper> make_packet_stepper(const StepOptions& options = {}) const {
        (void)options;
        return nullptr;
    }
    /// The reference packet loop: rays[0, n) traced as one packet, each ray's hit and work and the
    /// packet's counts (any output may be null); `split_below` as PacketStepper::set_split_below,
    /// `options` as make_packet_stepper's (the any-hit order is the one that changes the walk).
    /// The default drives make_packet_stepper(); throws rtsim::Error where the kind has none.
    virtual void trace_packet(const Ray* rays, const TraversalMode* modes, uint32_t n, Hit* hits, WorkCounts* work,
                              PacketCounts* counts, float split_below = 0.0f, const StepOptions& options = {}) const;
    /// Treelets (or cell blocks) of at most `budget_bytes`, keyed by StepPlan::locality.
    virtual LocalityPartition partition(uint64_t budget_bytes) const = 0;
    /// Operation kinds the steppers issue (the model instantiates a pipeline for each).
    virtual std::vector<OpKind> op_kinds() const = 0;
    /// Deepest traversal stack a ray can need (sizes the model's stack spill area).
    virtual uint32_t max_stack_entries() const = 0;
    /// What the structure offers the techniques a run may ask for, as its registry entry declares
    /// it (capabilities.h; a two-level structure's follow from its BLAS kind's).
    virtual AccelCapabilities capabilities() const;
    /// Bytes of one traversal stack entry in this structure's hardware: what a spill moves and
    /// what the on-chip stack holds per entry (a BVH's 8: node and entry distance; a kd-tree's
    /// 12: node, tnear, tfar; an octree's 32: node, tnear and the cell's six plane distances).
    uint32_t stack_entry_bytes() const { return capabilities().stack_entry_bytes; }
    /// True when some triangle is alpha-MASKed (the any-hit stage is then needed).
    bool has_anyhit_triangles() const;
    /// True when some record is a sphere (the sphere pipeline is then needed).
    bool has_spheres() const;
    /// True when some record is a capsule (the capsule pipeline is then needed).
    bool has_capsules() const;
    /// True when some record is a sphere or a capsule (leaves then split their tests by kind).
    bool has_curved() const;
    /// Frames of an animated scene the image holds (docs/accel.md, "Frames"): 1, or for a
    /// two-level image traced with --frames, one TLAS per frame over the same BLASes.
    virtual uint32_t frame_count() const { return 1; }
    /// Makes frame `f` the one steppers traverse from their next step on (a driver binding that
    /// frame's top-level buffer). Only between rays: no ray may be in flight. Throws
    /// rtsim::Error if f >= frame_count().
    virtual void bind_frame(uint32_t f);

protected:
    /// `kinds` (the structure's own operations) and those its records call for: the any-hit
    /// stage for alpha-MASK triangles, the sphere and capsule pipelines for curved ones.
    std::vector<OpKind> with_record_kinds(std::vector<OpKind> kinds) const;

    AccelImage m_image;
    /// The triangles the steppers read, plain or decoded from compressed leaves (leaf_blocks.h);
    /// opened by structures that have a triangle region.
    TriangleStore m_triangles;

private:
    /// True when some record of the image's own triangle regions has `flag` (hw_triangle.h).
    bool has_flagged_records(uint32_t flag) const;
};

/// How to build a structure: which kind, which builder for its tree, and the builder's config.
struct AccelOptions {
    std::string kind = "bvh2";        ///< accel_kinds() name
    std::string builder;              ///< empty: the kind's default (its first); accel_kinds() lists each kind's builders
    BuildConfig build;
    /// Overrides of the kind's and builder's documented settings, {name: value} (docs/accel.md,
    /// "Builder settings"; accel_kinds() lists each builder's): applied over `build` and the other
    /// Configs' defaults; unknown names are refused.
    nlohmann::json settings = nlohmann::json::object();
    /// Two levels (docs/accel.md, "Two-level structures"): a BLAS of `kind` per mesh in object
    /// space and a binary TLAS over the instances; the image's kind is then "two_level".
    bool two_level = false;
    /// Threads the build may use where its builder can ("binned": the binary build tree). The
    /// image is the same, byte for byte, for any count; 1 builds on the calling thread only.
    unsigned build_threads = 1;
    /// Moving geometry: the tree to refit and where the built tree goes (null: build afresh,
    /// keep nothing).
    TreeReuse* tree_reuse = nullptr;
};

struct AccelKindInfo {
    std::string name;
    std::string description;
    std::vector<std::string> builders;  ///< builders this kind accepts (first: default)
    AccelCapabilities capabilities;     ///< what it offers a run's techniques (capabilities.h)
};

/// The settings a kind's builder takes, as a schema {name: {type, default, unit, min, max, doc}}.
/// Throws rtsim::Error if the kind or builder is unknown.
nlohmann::json accel_settings_schema(const std::string& kind, const std::string& builder = "");

/// Every registered structure, in a stable order.
const std::vector<AccelKindInfo>& accel_kinds();
/// The capabilities a kind's registry entry declares (capabilities.h); "two_level" with the
/// BLAS kind `blas_kind`. Throws rtsim::Error listing the known kinds if `kind` is none.
AccelCapabilities accel_capabilities(const std::string& kind, const std::string& blas_kind = "bvh2");
/// A structure one step from a trace's (what the verdict weighs as a structural alternative and
/// `rtsim trace --alternatives` traces beside it): `key` is `accel` (another kind: a wide BVH for
/// a binary or other kind, compressed nodes for a wide fp32 one, after Ylitie, Karras & Laine
/// 2017) or `compressed_leaves` (`value` "true"), the build setting.
struct StructureAlternative {
    std::string key, value;
};
/// None for compressed nodes or two levels; compressed leaves where the kind may store them and
/// the scene has no curved primitives (leaf blocks index triangle vertices).
std::vector<StructureAlternative> structure_alternatives(const std::string& kind, bool compressed_leaves,
                                                         bool curved);
/// Where `rtsim trace --alternatives` writes an alternative, relative to the trace's folder:
/// "alternatives/<key>=<value>".
std::string structure_alternative_dir(const StructureAlternative& alternative);
/// Throws rtsim::Error listing the known kinds and builders if the options name none.
void validate_accel_options(const AccelOptions& options);
/// Builds the image of a structure over a flattened scene (two-level: over its meshes and
/// instances, flattened or not); build_ms is the wall time it took.
AccelImage build_accel(const Scene& scene, const AccelOptions& options);
/// Wraps an image (e.g. read from a trace) in its kind's Accel, validating it structurally;
/// throws rtsim::Error naming `source` and the first problem.
std::unique_ptr<Accel> load_accel(AccelImage image, const std::string& source = "accel image");

/// Drives a stepper over a ray to the end: the definition every fused loop is tested against.
/// With a final stepper type (a structure's own, on the caller's stack) the calls are direct.
template <class S>
Hit trace_with_stepper(S& stepper, const Ray& ray, TraversalMode mode, WorkCounts* work = nullptr) {
    stepper.begin(ray, mode);
    while (!stepper.done()) stepper.execute();
    if (work) *work = stepper.work();
    return stepper.hit();
}

}  // namespace rtsim
