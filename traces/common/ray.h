#pragma once
// Rays, hits and per-ray work counts: the records a trace carries (see docs/trace_format.md).
#include <cstdint>
#include <limits>

#include <glm/glm.hpp>

namespace rtsim {

using Vec3 = glm::vec3;

/// What a ray is for. Values are stored in traces; never renumber.
enum class RayKind : uint8_t {
    primary = 0,
    shadow = 1,      ///< occlusion (any-hit) ray towards a light
    reflection = 2,  ///< mirror ray from a metallic or smooth surface
    diffuse = 3,     ///< cosine-weighted bounce
    refraction = 4,  ///< transmitted ray through a transmissive material
};
constexpr int kRayKindCount = 5;
const char* ray_kind_name(RayKind kind);
/// Parses "primary", "shadow", ...; throws rtsim::Error naming the text otherwise.
RayKind parse_ray_kind(const char* text);

/// Closest hit (the nearest surface) or any hit (occlusion: stop at the first accepted hit).
enum class TraversalMode : uint8_t { closest_hit = 0, any_hit = 1 };

/// A ray as traced: the segment origin + t * direction for t in [tmin, tmax].
/// The direction is not required to be normalised.
struct Ray {
    Vec3 origin{0.0f};
    float tmin = 0.0f;
    Vec3 direction{0.0f, 0.0f, 1.0f};
    float tmax = std::numeric_limits<float>::infinity();
};

/// Closest (or any) hit of a ray. prim is the stable primitive id (Scene docs), -1 for a miss.
struct Hit {
    int32_t prim = -1;
    int32_t inst = -1;  ///< instance (glTF node / EXT_mesh_gpu_instancing entry) of the hit
    float t = std::numeric_limits<float>::infinity();
    float u = 0.0f;  ///< barycentric weight of vertex 1
    float v = 0.0f;  ///< barycentric weight of vertex 2
    bool valid() const { return prim >= 0; }
};

/// Work one ray caused in the reference traversal; the model must count the same. Names are
/// neutral so every acceleration structure reports in them (docs/accel.md).
struct WorkCounts {
    uint32_t steps = 0;        ///< traversal steps that fetched a node or a cell
    uint32_t box_tests = 0;    ///< ray/box tests (a node's child boxes, a grid's bounds)
    uint32_t tri_tests = 0;    ///< ray/triangle tests
    uint32_t anyhit_calls = 0; ///< alpha-mask (any-hit) evaluations on MASK triangles
    uint32_t transforms = 0;   ///< instance transforms (two-level structures)
    uint32_t cell_steps = 0;   ///< 3D-DDA steps from cell to cell (grids)
    uint32_t plane_tests = 0;  ///< ray/split-plane tests (kd-trees, BIH)
    uint32_t refs = 0;         ///< primitive references fetched (structures with index lists)
    /// The model's mailbox (docs/accel.md, "Mailboxes"; never in a trace: a trace's work is the
    /// structure's without one): references looked up, and those found, whose triangle was then
    /// neither fetched nor tested. With a mailbox tri_tests counts the tests run, and
    /// tri_tests + mailbox_hits equals the triangle tests without one.
    uint32_t mailbox_lookups = 0;
    uint32_t mailbox_hits = 0;

    WorkCounts& operator+=(const WorkCounts& o) {
        steps += o.steps;
        box_tests += o.box_tests;
        tri_tests += o.tri_tests;
        anyhit_calls += o.anyhit_calls;
        transforms += o.transforms;
        cell_steps += o.cell_steps;
        plane_tests += o.plane_tests;
        refs += o.refs;
        mailbox_lookups += o.mailbox_lookups;
        mailbox_hits += o.mailbox_hits;
        return *this;
    }
    bool operator==(const WorkCounts& o) const {
        return steps == o.steps && box_tests == o.box_tests && tri_tests == o.tri_tests &&
               anyhit_calls == o.anyhit_calls && transforms == o.transforms &&
               cell_steps == o.cell_steps && plane_tests == o.plane_tests && refs == o.refs &&
               mailbox_lookups == o.mailbox_lookups && mailbox_hits == o.mailbox_hits;
    }
    bool operator!=(const WorkCounts& o) const { return !(*this == o); }
    /// The counts the same traversal has without a mailbox (what a trace records): the skipped
    /// tests counted back, the mailbox's own counts dropped.
    WorkCounts without_mailbox() const {
        WorkCounts w = *this;
        w.tri_tests += mailbox_hits;
        w.mailbox_lookups = w.mailbox_hits = 0;
        return w;
    }
};

/// True when a ray may be traversed: finite origin and direction, non-zero direction,
/// tmin <= tmax, tmin not NaN. Rays failing this are rejected, counted and reported.
bool ray_is_valid(const Ray& ray);

}  // namespace rtsim
