// Parametric surfaces tessellated into indexed triangles with consistent outward winding.
#include <algorithm>
#include <cmath>
#include <functional>

#include "traces/scene/procedural_shapes.h"

namespace rtsim {

namespace {

/// Grid of (nu x nv) quads over point(i, j); wrapped dimensions reuse their first row so seams are
/// watertight. Triangles (a, b, c), (a, c, d) face along d/du x d/dv; degenerate ones are dropped.
void add_grid(TriangleSoup& soup, int nu, int nv, bool wrap_u, bool wrap_v,
              const std::function<Vec3(int, int)>& point) {
    int cols = wrap_u ? nu : nu + 1;
    int rows = wrap_v ? nv : nv + 1;
    uint32_t base = uint32_t(soup.vertices.size());
    for (int i = 0; i < cols; ++i)
        for (int j = 0; j < rows; ++j) soup.add_vertex(point(i, j));
    auto id = [&](int i, int j) { return base + uint32_t((i % cols) * rows + (j % rows)); };
    auto emit = [&](uint32_t a, uint32_t b, uint32_t c) {
        const auto& v = soup.vertices;
        if (v[a] == v[b] || v[b] == v[c] || v[a] == v[c]) return;
        soup.add_triangle(a, b, c);
    };
    for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j) {
            uint32_t a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
            emit(a, b, c);
            emit(a, c, d);
        }
}

}  // namespace

void add_lathe(TriangleSoup& soup, const std::vector<glm::vec2>& profile, int segments,
               const glm::dmat4& m) {
    // Point (r sin t, y, r cos t): d/dt x d/dy points away from the axis.
    add_grid(soup, segments, int(profile.size()) - 1, true, false, [&](int i, int j) {
        double t = 2.0 * kPi * i / segments;
        glm::dvec4 p(profile[size_t(j)].x * std::sin(t), profile[size_t(j)].y,
                     profile[size_t(j)].x * std::cos(t), 1.0);
        return Vec3(m * p);
    });
}

void add_sphere(TriangleSoup& soup, const Vec3& center, float radius, int rings, int segments) {
    std::vector<glm::vec2> profile;
    for (int k = 0; k <= rings; ++k) {
        double phi = kPi * k / rings;  // 0 at the bottom pole
        profile.emplace_back(k == 0 || k == rings ? 0.0f : float(radius * std::sin(phi)),
                             float(-radius * std::cos(phi)));
    }
    glm::dmat4 m(1.0);
    m[3] = glm::dvec4(glm::dvec3(center), 1.0);
    add_lathe(soup, profile, segments, m);
}

void add_torus(TriangleSoup& soup, float major, float minor, int major_segs, int minor_segs,
               const glm::dmat4& m) {
    // d/dtheta x d/dphi points away from the tube's centre line.
    add_grid(soup, major_segs, minor_segs, true, true, [&](int i, int j) {
        double t = 2.0 * kPi * i / major_segs, f = 2.0 * kPi * j / minor_segs;
        double ring = major + minor * std::cos(f);
        return Vec3(m * glm::dvec4(ring * std::cos(t), ring * std::sin(t), minor * std::sin(f), 1.0));
    });
}

void add_tube(TriangleSoup& soup, const std::vector<Vec3>& path, const std::vector<float>& radius,
              int sides) {
    // Frames (T, N, B) right-handed, N carried along by parallel transport (no flips);
    // d/dphi x d/ds = B x T = N points outward at phi = 0.
    size_t n = path.size();
    std::vector<glm::dvec3> nrm(n), bin(n);
    for (size_t k = 0; k < n; ++k) {
        glm::dvec3 t = glm::normalize(glm::dvec3(path[std::min(k + 1, n - 1)] - path[k > 0 ? k - 1 : 0]));
        glm::dvec3 prev = k > 0 ? nrm[k - 1] : glm::cross(std::abs(t.z) < 0.9 ? glm::dvec3(0, 0, 1)
                                                                              : glm::dvec3(1, 0, 0), t);
        nrm[k] = glm::normalize(prev - glm::dot(prev, t) * t);
        bin[k] = glm::cross(t, nrm[k]);
    }
    add_grid(soup, sides, int(n) - 1, true, false, [&](int i, int j) {
        double f = 2.0 * kPi * i / sides;
        glm::dvec3 off = double(radius[size_t(j)]) * (std::cos(f) * nrm[size_t(j)] + std::sin(f) * bin[size_t(j)]);
        return Vec3(glm::dvec3(path[size_t(j)]) + off);
    });
}

Material make_material(const std::string& name, const Vec3& color, float metallic, float roughness,
                       const Vec3& emissive) {
    Material m;
    m.name = name;
    m.base_color = glm::vec4(color, 1.0f);
    m.metallic = metallic;
    m.roughness = roughness;
    m.emissive = emissive;
    return m;
}

}  // namespace rtsim
