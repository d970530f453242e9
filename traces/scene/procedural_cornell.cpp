// The Cornell box (Goral, Torrance, Greenberg & Battaile 1984; dimensions after the Cornell
// "Cornell Box Data" page, in units of 100 mm): five walls, an emissive ceiling quad, a tall mirror
// box and a diffuse sphere. Deterministic: no random numbers at all.
#include <glm/gtc/matrix_transform.hpp>

#include "traces/scene/procedural_shapes.h"

namespace rtsim {

std::string write_cornell(const std::string& dir, const ProceduralOptions& options) {
    (void)options;
    const float s = 5.55f;  // box edge
    TriangleSoup white, red, green, light, mirror;

    // Walls face inward; the front (z = 0) is open towards the camera.
    white.add_quad({0, 0, 0}, {s, 0, 0}, {s, 0, s}, {0, 0, s}, {0, 1, 0});     // floor
    white.add_quad({0, s, 0}, {s, s, 0}, {s, s, s}, {0, s, s}, {0, -1, 0});    // ceiling
    white.add_quad({0, 0, s}, {s, 0, s}, {s, s, s}, {0, s, s}, {0, 0, -1});    // back
    red.add_quad({s, 0, 0}, {s, 0, s}, {s, s, s}, {s, s, 0}, {-1, 0, 0});      // left (seen from camera)
    green.add_quad({0, 0, 0}, {0, 0, s}, {0, s, s}, {0, s, 0}, {1, 0, 0});     // right

    // Area light just below the ceiling, facing down.
    const float ly = s - 0.01f;
    light.add_quad({2.13f, ly, 2.27f}, {3.43f, ly, 2.27f}, {3.43f, ly, 3.32f}, {2.13f, ly, 3.32f},
                   {0, -1, 0});

    // Tall box, rotated 17 degrees about the vertical, as a mirror.
    glm::dmat4 m = glm::translate(glm::dmat4(1.0), glm::dvec3(3.68, 1.65, 3.51));
    m = glm::rotate(m, glm::radians(17.0), glm::dvec3(0, 1, 0));
    m = glm::scale(m, glm::dvec3(1.65, 3.30, 1.65));
    mirror.add_box(m);

    // Diffuse tessellated sphere where the classic short box stands.
    add_sphere(white, {1.86f, 0.9f, 1.69f}, 0.9f, 32, 64);

    GltfWriter w;
    int m_white = w.add_material(make_material("white", {0.73f, 0.73f, 0.73f}, 0.0f, 1.0f));
    int m_red = w.add_material(make_material("red", {0.65f, 0.05f, 0.05f}, 0.0f, 1.0f));
    int m_green = w.add_material(make_material("green", {0.12f, 0.45f, 0.15f}, 0.0f, 1.0f));
    int m_light = w.add_material(make_material("light", {0.78f, 0.78f, 0.78f}, 0.0f, 1.0f,
                                               {17.0f, 12.0f, 4.0f}));
    int m_mirror = w.add_material(make_material("mirror", {0.95f, 0.95f, 0.95f}, 1.0f, 0.0f));
    int mesh = w.add_mesh("cornell_box", {{&white, m_white},
                                          {&red, m_red},
                                          {&green, m_green},
                                          {&light, m_light},
                                          {&mirror, m_mirror}});
    w.add_mesh_node("cornell_box", mesh);
    w.add_camera("camera", {2.78f, 2.73f, -8.0f}, {2.78f, 2.73f, 0.0f}, 0.686f, 1.0f);
    return w.write(dir, "cornell");
}

}  // namespace rtsim
