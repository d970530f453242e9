// Scenes of spheres and capsules (docs/accel.md, "Spheres and capsules"), written as glTF POINTS
// and LINES primitives with a _RADIUS attribute:
//  - particles: a cloud of small spheres (a particle system's sprites as geometry) around a
//    mirror sphere, over a floor, lit by a point light: primary, shadow, reflection and
//    diffuse rays, spheres and triangles in one structure;
//  - furball: the hairball's counterpart in spheres, fur grown from a core sphere, each strand
//    a chain of overlapping beads (how hair was traced before swept-sphere primitives; the
//    strands are as thin and as crossed as the hairball's ribbons, but round);
//  - furball_capsules: the same strands as chains of capsules through every sixth bead (glTF
//    LINES with _RADIUS), 8 primitives a strand instead of 48;
//  - furball_herd: nine furballs of capsules, one mesh placed nine times (two levels);
//  - exploding_furball: the capsules flying apart over frames (a deforming mesh).
// Each has a twin of triangles, "particles_mesh" and "furball_mesh": the same spheres, each an
// icosahedron with its vertices on the sphere (20 triangles), so a study can set native spheres
// beside the coarsest tessellation a renderer would use.
// O(N) and deterministic: every particle and strand draws from its own counter-based stream.
#include <cmath>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "traces/common/rng.h"
#include "traces/scene/gltf_writer.h"
#include "traces/scene/procedural_shapes.h"

namespace rtsim {

namespace {

constexpr uint32_t kParticles = 40000;
constexpr uint32_t kStrands = 2000;
constexpr int kBeads = 48;            ///< spheres per strand
constexpr float kCoreRadius = 0.6f;   ///< the furball's body
constexpr float kBeadRadius = 0.004f;
constexpr float kBeadStep = 0.006f;   ///< centre to centre: beads overlap by a third
constexpr float kFurCurl = 0.25f;     ///< random turn per bead
constexpr int kCapsuleBeads = 6;      ///< beads a capsule of furball_capsules spans

Vec3 random_unit(Rng& rng) {
    const float z = 2.0f * rng.next() - 1.0f, phi = 6.28318530718f * rng.next();
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    return {r * std::cos(phi), r * std::sin(phi), z};
}

struct Spheres {
    std::vector<Vec3> centres;
    std::vector<float> radii;
};

/// An icosahedron inscribed in each sphere (vertices on it), faces wound outward.
TriangleSoup icosahedra(const Spheres& s) {
    const float g = 1.6180339887f;
    Vec3 unit[12] = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                     {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
    for (Vec3& v : unit) v = glm::normalize(v);
    static const uint32_t kFaces[60] = {0, 11, 5, 0, 5,  1, 0, 1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
                                        4, 11, 10, 2, 10, 7, 6, 7, 1, 8, 3, 9, 4, 3, 4, 2, 3, 2, 6, 3,
                                        6, 8, 3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1};
    TriangleSoup soup;
    soup.vertices.reserve(12 * s.centres.size());
    soup.indices.reserve(60 * s.centres.size());
    for (size_t i = 0; i < s.centres.size(); ++i) {
        const uint32_t base = uint32_t(soup.vertices.size());
        for (const Vec3& v : unit) soup.add_vertex(s.centres[i] + s.radii[i] * v);
        for (int f = 0; f < 60; f += 3) soup.add_triangle(base + kFaces[f], base + kFaces[f + 1], base + kFaces[f + 2]);
    }
    return soup;
}

/// Adds `s` as a mesh node: spheres, or their icosahedra.
void add_spheres(GltfWriter& w, const std::string& name, const Spheres& s, int material, bool tessellated) {
    if (!tessellated) {
        w.add_mesh_node(name, w.add_sphere_mesh(name, s.centres, s.radii, material));
        return;
    }
    const TriangleSoup soup = icosahedra(s);
    w.add_mesh_node(name, w.add_mesh(name, {{&soup, material}}));
}

}  // namespace

std::string write_particles(const std::string& dir, const ProceduralOptions& options, bool tessellated) {
    Spheres cloud;
    std::vector<Vec3>& centres = cloud.centres;
    std::vector<float>& radii = cloud.radii;
    centres.reserve(kParticles);
    radii.reserve(kParticles);
    for (uint32_t i = 0; i < kParticles; ++i) {
        Rng rng(hash_combine(options.seed, 0x70617274ull /*"part"*/, i));
        // A shell between the mirror sphere and radius 1.2, denser towards the inside.
        const float r = 0.45f + 0.75f * rng.next() * rng.next();
        centres.push_back(random_unit(rng) * r + Vec3(0.0f, 1.2f, 0.0f));
        radii.push_back(0.006f + 0.014f * rng.next());
    }
    TriangleSoup floor;
    floor.add_quad({-3, 0, -3}, {3, 0, -3}, {3, 0, 3}, {-3, 0, 3}, {0, 1, 0});

    GltfWriter w;
    const int dust = w.add_material(make_material("particle", {0.85f, 0.55f, 0.25f}, 0.0f, 0.8f));
    const int mirror = w.add_material(make_material("mirror", {0.95f, 0.95f, 0.95f}, 1.0f, 0.05f));
    const int ground = w.add_material(make_material("floor", {0.6f, 0.6f, 0.62f}, 0.0f, 1.0f));
    add_spheres(w, "particles", cloud, dust, tessellated);
    add_spheres(w, "mirror_sphere", Spheres{{{0.0f, 1.2f, 0.0f}}, {0.35f}}, mirror, tessellated);
    w.add_mesh_node("floor", w.add_mesh("floor", {{&floor, ground}}));
    w.add_light("key_light", LightType::point, {2.5f, 4.0f, 2.5f}, {0, 0, 0}, {1, 1, 1}, 80.0f);
    w.add_camera("camera", {0.0f, 1.5f, 3.6f}, {0.0f, 1.1f, 0.0f}, 0.75f, 1.0f);
    return w.write(dir, tessellated ? "particles_mesh" : "particles");
}

/// How the furball's strands are written: beads (spheres), their icosahedra, or capsules.
enum class Fur { beads, icosahedra, capsules };

/// The furball's strands as beads: kStrands chains of kBeads overlapping spheres grown from the
/// core, curling but always outward, tapering to half the bead radius.
Spheres fur_beads(const ProceduralOptions& options) {
    Spheres fur_spheres;
    std::vector<Vec3>& centres = fur_spheres.centres;
    std::vector<float>& radii = fur_spheres.radii;
    centres.reserve(size_t(kStrands) * kBeads);
    for (uint32_t s = 0; s < kStrands; ++s) {
        Rng rng(hash_combine(options.seed, 0x66757262ull /*"furb"*/, s));
        const Vec3 root = random_unit(rng);
        Vec3 p = root * (kCoreRadius - kBeadRadius), dir = root;
        for (int b = 0; b < kBeads; ++b) {
            centres.push_back(p);
            radii.push_back(kBeadRadius * (1.0f - 0.5f * float(b) / kBeads));  // strands taper
            // Curl, but keep growing outward (never back into the body).
            dir = glm::normalize(dir + kFurCurl * random_unit(rng));
            if (glm::dot(dir, glm::normalize(p)) < 0.2f) dir = glm::normalize(dir + glm::normalize(p));
            p += kBeadStep * dir;
        }
    }
    return fur_spheres;
}

/// The furball's material (strands and body alike).
int add_fur_material(GltfWriter& w) { return w.add_material(make_material("fur", {0.45f, 0.3f, 0.18f}, 0.0f, 0.6f)); }

/// The strands as a capsule mesh: each a chain of capsules through every kCapsuleBeads-th bead
/// and its last one, a vertex's radius its bead's (a capsule tapers from one end's to the other's).
int add_fur_capsules(GltfWriter& w, const Spheres& beads, int material) {
    std::vector<Vec3> vertices;
    std::vector<float> vertex_radii;
    std::vector<uint32_t> segments;
    for (uint32_t s = 0; s < kStrands; ++s) {
        const size_t first = size_t(s) * kBeads;
        for (int b = 0; b < kBeads; b += kCapsuleBeads) {
            const int next = std::min(b + kCapsuleBeads, kBeads - 1);
            if (b == 0) vertices.push_back(beads.centres[first]), vertex_radii.push_back(beads.radii[first]);
            vertices.push_back(beads.centres[first + size_t(next)]);
            vertex_radii.push_back(beads.radii[first + size_t(next)]);
            segments.insert(segments.end(), {uint32_t(vertices.size() - 2), uint32_t(vertices.size() - 1)});
            if (next == kBeads - 1) break;
        }
    }
    return w.add_capsule_mesh("fur", vertices, vertex_radii, segments, material);
}

std::string write_furball(const std::string& dir, const ProceduralOptions& options, Fur as) {
    const Spheres fur_spheres = fur_beads(options);
    GltfWriter w;
    const int fur = add_fur_material(w);
    const bool tessellated = as == Fur::icosahedra;
    if (as == Fur::capsules) w.add_mesh_node("fur", add_fur_capsules(w, fur_spheres, fur));
    else add_spheres(w, "fur", fur_spheres, fur, tessellated);
    add_spheres(w, "body", Spheres{{{0.0f, 0.0f, 0.0f}}, {kCoreRadius}}, fur, tessellated);
    w.add_light("key_light", LightType::point, {2.5f, 3.0f, 2.5f}, {0, 0, 0}, {1, 1, 1}, 60.0f);
    w.add_camera("camera", {0.0f, 0.3f, 3.2f}, {0, 0, 0}, 0.7f, 1.0f);
    return w.write(dir, as == Fur::beads ? "furball" : (tessellated ? "furball_mesh" : "furball_capsules"));
}

/// exploding_furball: furball_capsules' strands flying apart over frames (each capsule moves
/// away from the centre at its own speed, glTF extras' scatter motion, as exploding_hairball's
/// triangles do), the body sphere still: curved primitives in a deforming mesh, whose BLAS is
/// rebuilt or refitted per frame (--frame-policy).
std::string write_exploding_furball(const std::string& dir, const ProceduralOptions& options) {
    const Spheres beads = fur_beads(options);
    GltfWriter w;
    const int fur = add_fur_material(w);
    const int ground = w.add_material(make_material("floor", {0.6f, 0.6f, 0.6f}, 0.0f, 1.0f));
    const int fur_mesh = add_fur_capsules(w, beads, fur);
    // Over 60 frames (1 s) the fur spreads to about 2-3x the ball.
    w.set_mesh_motion(fur_mesh, scatter_motion(0.1f, 1.2f, options.seed));
    w.add_mesh_node("fur", fur_mesh);
    add_spheres(w, "body", Spheres{{{0.0f, 0.0f, 0.0f}}, {kCoreRadius}}, fur, false);
    TriangleSoup floor;
    floor.add_quad({-5, -1.0f, -5}, {5, -1.0f, -5}, {5, -1.0f, 5}, {-5, -1.0f, 5}, {0, 1, 0});
    w.add_mesh_node("floor", w.add_mesh("floor", {{&floor, ground}}));
    w.add_light("key_light", LightType::point, {2.5f, 3.0f, 2.5f}, {0, 0, 0}, {1, 1, 1}, 60.0f);
    w.add_camera("camera", {0.0f, 0.5f, 4.4f}, {0, 0, 0}, 0.8f, 1.0f);
    return w.write(dir, "exploding_furball");
}

constexpr int kHerdSide = 3;  ///< furball_herd: kHerdSide^2 furballs

/// furball_herd: furball_capsules' fur and body placed kHerdSide^2 times on a floor, each turned
/// about the vertical and scaled uniformly (0.6-1.1): instances of curved primitives, traced in
/// two levels (each mesh's BLAS once, a TLAS over the placements), as hair and grass are.
std::string write_furball_herd(const std::string& dir, const ProceduralOptions& options) {
    const Spheres beads = fur_beads(options);
    GltfWriter w;
    const int fur = add_fur_material(w);
    const int ground = w.add_material(make_material("floor", {0.55f, 0.6f, 0.5f}, 0.0f, 1.0f));
    const int fur_mesh = add_fur_capsules(w, beads, fur);
    const int body_mesh = w.add_sphere_mesh("body", {{0.0f, 0.0f, 0.0f}}, {kCoreRadius}, fur);
    for (int i = 0; i < kHerdSide * kHerdSide; ++i) {
        Rng rng(hash_combine(options.seed, 0x68657264ull /*"herd"*/, uint64_t(i)));
        const float scale = 0.6f + 0.5f * rng.next(), turn = 6.28318530718f * rng.next();
        const Vec3 at(2.2f * float(i % kHerdSide - 1), (kCoreRadius + 0.25f) * scale, -2.2f * float(i / kHerdSide));
        glm::dmat4 m = glm::translate(glm::dmat4(1.0), glm::dvec3(at));
        m = glm::rotate(m, double(turn), glm::dvec3(0, 1, 0));
        m = glm::scale(m, glm::dvec3(scale));
        const std::string name = "furball_" + std::to_string(i);
        w.add_mesh_node(name + "_fur", fur_mesh, m);
        w.add_mesh_node(name + "_body", body_mesh, m);
    }
    TriangleSoup floor;
    floor.add_quad({-4, 0, 2}, {4, 0, 2}, {4, 0, -7}, {-4, 0, -7}, {0, 1, 0});
    w.add_mesh_node("floor", w.add_mesh("floor", {{&floor, ground}}));
    w.add_light("key_light", LightType::point, {3.0f, 5.0f, 2.0f}, {0, 0, -2}, {1, 1, 1}, 200.0f);
    w.add_camera("camera", {0.0f, 3.6f, 5.2f}, {0.0f, 0.2f, -2.4f}, 0.75f, 1.0f);
    return w.write(dir, "furball_herd");
}

std::string write_particles(const std::string& dir, const ProceduralOptions& options) {
    return write_particles(dir, options, false);
}
std::string write_particles_mesh(const std::string& dir, const ProceduralOptions& options) {
    return write_particles(dir, options, true);
}
std::string write_furball(const std::string& dir, const ProceduralOptions& options) {
    return write_furball(dir, options, Fur::beads);
}
std::string write_furball_capsules(const std::string& dir, const ProceduralOptions& options) {
    return write_furball(dir, options, Fur::capsules);
}
std::string write_furball_mesh(const std::string& dir, const ProceduralOptions& options) {
    return write_furball(dir, options, Fur::icosahedra);
}

}  // namespace rtsim
