#include "traces/raygen/surface.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "traces/common/round_cone.h"

namespace rtsim {

namespace {

// gamma(n) of Higham / pbrt: bound on the relative error of n float operations.
constexpr float gamma(int n) {
    constexpr float eps = std::numeric_limits<float>::epsilon() * 0.5f;
    return (n * eps) / (1.0f - n * eps);
}

/// The error bound `gamma(n)` of a point whose terms sum to `magnitude` per axis, with a floor of
/// its largest axis (pbrt's bound is zero in an axis where every term is 0, e.g. a wall in the
/// plane x = 0, and then the offset vanishes while the intersection's arithmetic can still turn
/// the exact t = 0 of a self-hit into ~1e-9; the floor keeps it non-zero and scale-invariant).
Vec3 point_error(const Vec3& magnitude, int n) {
    const float floor = std::max(magnitude.x, std::max(magnitude.y, magnitude.z));
    return gamma(n) * (magnitude + Vec3(floor));
}

/// The rest of a surface point from its geometric normal `n` (unit): which side the ray meets,
/// the normal turned towards the ray, the primitive and its material.
void face_the_ray(SurfacePoint& sp, Vec3 n, const Scene& scene, const Ray& ray, const Hit& hit) {
    sp.front = glm::dot(n, ray.direction) <= 0.0f;
    if (!sp.front) n = -n;
    sp.normal = n;
    sp.prim = uint32_t(hit.prim);
    sp.material = scene.material_of(uint32_t(hit.prim));
}

/// A curved primitive's hit point (pbrt-v4 Sphere::Intersect): the point on the ray,
/// reprojected onto the surface (from the centre of the swept sphere that touches the surface
/// there: the sphere's centre, or the point of the capsule's axis, plus that sphere's radius x
/// the unit normal from it), with pbrt's gamma(5) bound, taken here relative to the world origin
/// (the axis point's magnitude adds to it).
SurfacePoint curved_surface_point(const Scene& scene, const Ray& ray, const Hit& hit) {
    const CurvedShape shape = scene.curved_shape(uint32_t(hit.prim));
    float r = shape.r0;
    const glm::dvec3 p = glm::dvec3(ray.origin) + double(hit.t) * glm::dvec3(ray.direction);
    glm::dvec3 axis_point(shape.a);
    if (shape.capsule()) {
        const glm::dvec3 a(shape.a), b(shape.b);
        const double r0 = shape.r0, r1 = shape.r1, length = glm::length(b - a);
        if (end_sphere_holds_other(length, r0, r1)) {
            axis_point = r1 > r0 ? b : a;
            r = float(std::max(r0, r1));
        } else {
            // The sphere of centre a + s axis and radius r0 + k s touching p: its normal n has
            // n.axis = -k, so s = y + q k / sqrt(1 - k^2) (y along the axis, q across it).
            const glm::dvec3 axis = (b - a) / length;
            const double k = (r1 - r0) / length, y = glm::dot(p - a, axis);
            const double q = glm::length(p - a - y * axis);
            const double s = glm::clamp(y + q * k / std::sqrt(1.0 - k * k), 0.0, length);
            axis_point = a + s * axis;
            r = float(r0 + k * s);
        }
    }
    const Vec3 c(axis_point);
    const glm::dvec3 rel = p - axis_point;
    const double len = glm::length(rel);
    Vec3 n = len > 0.0 ? Vec3(rel / len) : Vec3(0.0f, 0.0f, 1.0f);
    SurfacePoint sp;
    sp.position = Vec3(axis_point + double(r) * glm::dvec3(n));
    sp.error = point_error(glm::abs(c) + glm::abs(r * n), 5);
    face_the_ray(sp, n, scene, ray, hit);
    return sp;
}

}  // namespace

SurfacePoint surface_point(const Scene& scene, const Ray& ray, const Hit& hit) {
    if (scene.is_curved(uint32_t(hit.prim))) return curved_surface_point(scene, ray, hit);
    const Triangle tri = scene.world_triangle(uint32_t(hit.prim));
    float b0 = 1.0f - hit.u - hit.v;
    SurfacePoint sp;
    // Barycentric interpolation and its error bound (pbrt-v4 Triangle::InteractionFromIntersection).
    sp.position = b0 * tri.v0 + hit.u * tri.v1 + hit.v * tri.v2;
    sp.error = point_error(glm::abs(b0 * tri.v0) + glm::abs(hit.u * tri.v1) + glm::abs(hit.v * tri.v2), 7);
    Vec3 n = glm::cross(tri.v1 - tri.v0, tri.v2 - tri.v0);
    float len = glm::length(n);
    n = len > 0.0f ? n / len : Vec3(0.0f, 0.0f, 1.0f);
    face_the_ray(sp, n, scene, ray, hit);
    return sp;
}

Vec3 offset_ray_origin(const SurfacePoint& p, const Vec3& w) {
    float d = glm::dot(glm::abs(p.normal), p.error);
    Vec3 offset = d * p.normal;
    if (glm::dot(w, p.normal) < 0.0f) offset = -offset;
    Vec3 po = p.position + offset;
    // Round away from the surface so the offset survives the addition.
    for (int i = 0; i < 3; ++i) {
        if (offset[i] > 0.0f)
            po[i] = std::nextafter(po[i], std::numeric_limits<float>::infinity());
        else if (offset[i] < 0.0f)
            po[i] = std::nextafter(po[i], -std::numeric_limits<float>::infinity());
    }
    return po;
}

void make_basis(const Vec3& n, Vec3* b1, Vec3* b2) {
    float sign = std::copysign(1.0f, n.z);
    float a = -1.0f / (sign + n.z);
    float b = n.x * n.y * a;
    *b1 = Vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    *b2 = Vec3(b, sign + n.y * n.y * a, -n.y);
}

Vec3 cosine_hemisphere(const Vec3& n, float u1, float u2) {
    float r = std::sqrt(u1);
    float phi = 6.28318530718f * u2;
    float x = r * std::cos(phi), y = r * std::sin(phi);
    float z = std::sqrt(std::max(0.0f, 1.0f - u1));
    Vec3 b1, b2;
    make_basis(n, &b1, &b2);
    return glm::normalize(x * b1 + y * b2 + z * n);
}

Vec3 reflect(const Vec3& d, const Vec3& n) { return d - 2.0f * glm::dot(d, n) * n; }

bool ggx_reflect(const Vec3& d, const Vec3& n, float alpha, float u1, float u2, Vec3* out) {
    Vec3 b1, b2;
    make_basis(n, &b1, &b2);
    const Vec3 wo = -d;
    const Vec3 ve(glm::dot(wo, b1), glm::dot(wo, b2), glm::dot(wo, n));  // in the normal's frame
    // Heitz 2018, listing 1: the view stretched to the unit-roughness configuration, a point
    // sampled on the projected hemisphere, and the normal unstretched.
    const Vec3 vh = glm::normalize(Vec3(alpha * ve.x, alpha * ve.y, ve.z));
    const float lensq = vh.x * vh.x + vh.y * vh.y;
    const Vec3 t1 = lensq > 0.0f ? Vec3(-vh.y, vh.x, 0.0f) / std::sqrt(lensq) : Vec3(1.0f, 0.0f, 0.0f);
    const Vec3 t2 = glm::cross(vh, t1);
    const float r = std::sqrt(u1), phi = 6.28318530718f * u2;
    const float p1 = r * std::cos(phi), s = 0.5f * (1.0f + vh.z);
    const float p2 = (1.0f - s) * std::sqrt(std::max(0.0f, 1.0f - p1 * p1)) + s * r * std::sin(phi);
    const Vec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
    const Vec3 ne = glm::normalize(Vec3(alpha * nh.x, alpha * nh.y, std::max(1e-6f, nh.z)));
    const Vec3 m = glm::normalize(ne.x * b1 + ne.y * b2 + ne.z * n);
    *out = glm::normalize(reflect(d, m));
    return glm::dot(*out, n) > 0.0f;
}

bool refract(const Vec3& d, const Vec3& n, float eta_i, float eta_t, Vec3* out) {
    float eta = eta_i / eta_t;
    float cos_i = -glm::dot(d, n);
    float sin2_t = eta * eta * std::max(0.0f, 1.0f - cos_i * cos_i);
    if (sin2_t >= 1.0f) return false;
    float cos_t = std::sqrt(1.0f - sin2_t);
    *out = glm::normalize(eta * d + (eta * cos_i - cos_t) * n);
    return true;
}

}  // namespace rtsim
