// The hairball: a ball densely filled with long, thin, curved strands, each a ribbon of thin
// triangles. In the spirit of Laine's "Hairball" benchmark scene (Laine & Karras 2010, "Efficient
// Sparse Voxel Octrees" test set), the worst case for BVH quality: long thin overlapping primitives.
// O(N) and deterministic: each strand draws from its own counter-based stream (seed, strand).
#include <algorithm>
#include <cmath>

#include "traces/common/error.h"
#include "traces/common/rng.h"
#include "traces/scene/procedural_shapes.h"
#include "traces/scene/scene.h"

namespace rtsim {

namespace {

constexpr int kSegments = 24;        ///< segments per strand (2 triangles each)
constexpr float kRadius = 1.0f;      ///< ball radius
constexpr float kStep = 0.04f;       ///< segment length
constexpr float kWidth = 0.003f;     ///< ribbon width
constexpr float kCurl = 0.35f;       ///< random turn per segment

Vec3 unit_vector(Rng& rng) {
    float z = 2.0f * rng.next() - 1.0f;
    float phi = 6.28318530718f * rng.next();
    float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    return {r * std::cos(phi), r * std::sin(phi), z};
}

/// Appends one strand of at most `budget` triangles; returns how many it emitted.
uint32_t add_strand(TriangleSoup& soup, Rng& rng, uint32_t budget) {
    Vec3 p = unit_vector(rng) * (kRadius * std::cbrt(rng.next()));
    Vec3 dir = unit_vector(rng);
    Vec3 side = glm::normalize(glm::cross(dir, unit_vector(rng)) + Vec3(1e-6f, 0.0f, 0.0f));
    auto add_pair = [&]() {
        soup.add_vertex(p - side * (0.5f * kWidth));
        return soup.add_vertex(p + side * (0.5f * kWidth)) - 1;
    };
    uint32_t prev = add_pair(), emitted = 0;
    for (int s = 0; s < kSegments && emitted < budget; ++s) {
        // Curl, step, and bounce off the ball's surface so the strand stays inside.
        dir = glm::normalize(dir + kCurl * unit_vector(rng));
        p += kStep * dir;
        float len = glm::length(p);
        if (len > kRadius) {
            Vec3 n = p / len;
            if (glm::dot(dir, n) > 0.0f) dir -= 2.0f * glm::dot(dir, n) * n;
            p = n * kRadius;
        }
        Vec3 ortho = side - glm::dot(side, dir) * dir;
        if (glm::length(ortho) > 1e-4f) side = glm::normalize(ortho);
        uint32_t cur = add_pair();
        soup.add_triangle(prev, prev + 1, cur);
        ++emitted;
        if (emitted < budget) {
            soup.add_triangle(prev + 1, cur + 1, cur);
            ++emitted;
        }
        prev = cur;
    }
    return emitted;
}

}  // namespace

TriangleSoup hairball_strands(uint32_t total, uint64_t seed) {
    TriangleSoup hair;
    uint64_t strands = (uint64_t(total) + 2 * kSegments - 1) / (2 * kSegments);
    hair.vertices.reserve(size_t(strands) * 2 * (kSegments + 1));
    hair.indices.reserve(size_t(total) * 3);
    uint32_t done = 0;
    for (uint64_t s = 0; done < total; ++s) {
        Rng rng(hash_combine(seed, 0x68616972ull /*"hair"*/, s));
        done += add_strand(hair, rng, total - done);
    }
    return hair;
}

std::string write_hairball(const std::string& dir, const ProceduralOptions& options) {
    uint32_t total = options.hairball_triangles;
    if (total == 0) throw Error("procedural scene 'hairball': hairball_triangles must be > 0");
    check_flat_size("procedural scene 'hairball'", total, "hairball_triangles=" + std::to_string(total));
    TriangleSoup hair = hairball_strands(total, options.seed);

    GltfWriter w;
    int mat = w.add_material(make_material("hair", {0.45f, 0.3f, 0.18f}, 0.0f, 0.6f));
    w.add_mesh_node("hairball", w.add_mesh("hairball", {{&hair, mat}}));
    w.add_light("key_light", LightType::point, {2.5f, 3.0f, 2.5f}, {0, 0, 0}, {1, 1, 1}, 60.0f);
    w.add_camera("camera", {0.0f, 0.3f, 3.2f}, {0, 0, 0}, 0.7f, 1.0f);
    return w.write(dir, "hairball");
}

}  // namespace rtsim
