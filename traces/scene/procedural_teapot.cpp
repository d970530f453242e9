// Teapot in a stadium (Haines' "teapot in a stadium" problem for uniform grids and BVHs): a small,
// detailed teapot-like object (~36k triangles: lathe body and lid, swept spout, torus handle) in
// the middle of a huge, sparse stadium (ground ~1000x the teapot, distant tiers of seating).
#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "traces/scene/procedural_shapes.h"

namespace rtsim {

namespace {

/// Catmull-Rom spline through `pts` (ends repeated), `per_span` samples per span, ends exact.
std::vector<glm::vec2> smooth(const std::vector<glm::vec2>& pts, int per_span) {
    std::vector<glm::vec2> out;
    size_t n = pts.size();
    for (size_t i = 0; i + 1 < n; ++i) {
        glm::vec2 p0 = pts[i > 0 ? i - 1 : 0], p1 = pts[i], p2 = pts[i + 1], p3 = pts[std::min(i + 2, n - 1)];
        for (int k = 0; k < per_span; ++k) {
            float t = float(k) / float(per_span), t2 = t * t, t3 = t2 * t;
            out.push_back(0.5f * ((2.0f * p1) + (-p0 + p2) * t + (2.0f * p0 - 5.0f * p1 + 4.0f * p2 - p3) * t2 +
                                  (-p0 + 3.0f * p1 - 3.0f * p2 + p3) * t3));
        }
    }
    out.push_back(pts.back());
    out.front() = pts.front();
    // Keep the overshoot of the spline inside the control points' height range (no dip below
    // the ground) and off the axis.
    float lo = pts.front().y, hi = pts.front().y;
    for (const glm::vec2& p : pts) lo = std::min(lo, p.y), hi = std::max(hi, p.y);
    for (glm::vec2& p : out) p = glm::vec2(std::max(p.x, 0.0f), std::clamp(p.y, lo, hi));
    return out;
}

void add_teapot(TriangleSoup& soup) {
    const int around = 128;
    // Body, closed: bottom pole, belly, shoulder, rim, flat top under the lid.
    add_lathe(soup,
              smooth({{0.0f, 0.0f}, {0.8f, 0.0f}, {1.05f, 0.05f}, {1.3f, 0.25f}, {1.45f, 0.55f},
                      {1.5f, 0.85f}, {1.42f, 1.15f}, {1.25f, 1.38f}, {1.08f, 1.5f}, {0.0f, 1.5f}},
                     8),
              around);
    // Lid with knob, bottom to top.
    add_lathe(soup,
              smooth({{1.1f, 1.49f}, {0.9f, 1.6f}, {0.4f, 1.7f}, {0.15f, 1.75f}, {0.12f, 1.85f},
                      {0.25f, 1.95f}, {0.2f, 2.02f}, {0.0f, 2.05f}},
                     8),
              around);
    // Spout: a tapering tube along a quadratic Bezier from the belly up and out.
    std::vector<Vec3> path;
    std::vector<float> radius;
    const Vec3 a(1.2f, 0.45f, 0.0f), b(2.2f, 0.6f, 0.0f), c(2.6f, 1.55f, 0.0f);
    for (int k = 0; k <= 40; ++k) {
        float t = k / 40.0f;
        path.push_back((1 - t) * (1 - t) * a + 2 * (1 - t) * t * b + t * t * c);
        radius.push_back(0.28f + (0.1f - 0.28f) * t);
    }
    add_tube(soup, path, radius, 24);
    // Handle: a torus standing in the XY plane behind the body.
    glm::dmat4 m = glm::translate(glm::dmat4(1.0), glm::dvec3(-1.45, 0.85, 0.0));
    m = glm::scale(m, glm::dvec3(0.8, 1.0, 1.0));
    add_torus(soup, 0.5f, 0.09f, 64, 16, m);
}

/// Tiers of seating (riser + tread per tier) and an outer wall, all facing the arena.
void add_stadium(TriangleSoup& ground, TriangleSoup& stands) {
    const float half = 1500.0f;
    ground.add_quad({-half, 0, -half}, {half, 0, -half}, {half, 0, half}, {-half, 0, half}, {0, 1, 0});
    const int segs = 96, tiers = 8;
    for (int i = 0; i < segs; ++i) {
        double t0 = 2.0 * kPi * i / segs, t1 = 2.0 * kPi * (i + 1) / segs;
        Vec3 d0(float(std::cos(t0)), 0.0f, float(std::sin(t0))), d1(float(std::cos(t1)), 0.0f, float(std::sin(t1)));
        Vec3 inward = -(d0 + d1);
        for (int k = 0; k < tiers; ++k) {
            float r = 900.0f + 40.0f * k, h = 15.0f * k, top = h + 15.0f;
            stands.add_quad(d0 * r + Vec3(0, h, 0), d1 * r + Vec3(0, h, 0), d1 * r + Vec3(0, top, 0),
                            d0 * r + Vec3(0, top, 0), inward);
            stands.add_quad(d0 * r + Vec3(0, top, 0), d1 * r + Vec3(0, top, 0),
                            d1 * (r + 40.0f) + Vec3(0, top, 0), d0 * (r + 40.0f) + Vec3(0, top, 0), {0, 1, 0});
        }
        float wr = 900.0f + 40.0f * tiers;
        stands.add_quad(d0 * wr + Vec3(0, 120, 0), d1 * wr + Vec3(0, 120, 0), d1 * wr + Vec3(0, 220, 0),
                        d0 * wr + Vec3(0, 220, 0), inward);
    }
}

}  // namespace

std::string write_teapot_stadium(const std::string& dir, const ProceduralOptions& options) {
    (void)options;
    TriangleSoup teapot, ground, stands;
    add_teapot(teapot);
    add_stadium(ground, stands);
    GltfWriter w;
    int m_tea = w.add_material(make_material("porcelain", {0.9f, 0.9f, 0.85f}, 0.0f, 0.2f));
    int m_grass = w.add_material(make_material("grass", {0.2f, 0.45f, 0.15f}, 0.0f, 1.0f));
    int m_stone = w.add_material(make_material("concrete", {0.55f, 0.55f, 0.55f}, 0.0f, 0.9f));
    w.add_mesh_node("teapot", w.add_mesh("teapot", {{&teapot, m_tea}}));
    w.add_mesh_node("stadium", w.add_mesh("stadium", {{&ground, m_grass}, {&stands, m_stone}}));
    w.add_light("sun", LightType::directional, {300.0f, 800.0f, 200.0f}, {0, 0, 0}, {1.0f, 0.95f, 0.85f}, 3.0f);
    w.add_camera("camera", {3.5f, 2.2f, 5.0f}, {0.0f, 0.9f, 0.0f}, 0.8f, 1.0f);
    return w.write(dir, "teapot_stadium");
}

}  // namespace rtsim
