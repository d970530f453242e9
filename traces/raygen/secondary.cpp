#include "traces/raygen/secondary.h"

#include <algorithm>
#include <cmath>

#include "traces/common/rng.h"
#include "traces/raygen/surface.h"

namespace rtsim {

namespace {

/// Shadow rays are aimed at the light with an unnormalised direction, so t = 1 at the light;
/// they stop just short of it (pbrt's ShadowEpsilon) so an emitter never occludes itself.
constexpr float kShadowEpsilon = 1e-4f;

bool spot_reaches(const Light& light, const Vec3& p) {
    if (light.type != LightType::spot) return true;
    float cos_angle = glm::dot(glm::normalize(p - light.position), glm::normalize(light.direction));
    return cos_angle >= std::cos(light.outer_cone);
}

void spawn_shadow_rays(const SpawnContext& ctx, const PendingRay& parent, const SurfacePoint& sp, Rng& rng,
                       std::vector<PendingRay>* out) {
    float u0 = rng.next(), u1 = rng.next(), u2 = rng.next();
    std::vector<LightSample> samples = light_samples(*ctx.scene, *ctx.plan, u0, u1, u2);
    for (size_t i = 0; i < samples.size(); ++i) {
        const LightSample& s = samples[i];
        bool punctual = i < ctx.scene->lights.size();
        if (punctual && !spot_reaches(ctx.scene->lights[i], sp.position)) continue;
        Vec3 towards = s.at_infinity ? s.direction : s.point - sp.position;
        float cos_theta = glm::dot(sp.normal, glm::normalize(towards));
        if (!(cos_theta > 0.0f)) continue;  // light behind the surface: no ray needed
        PendingRay r;
        r.kind = RayKind::shadow;
        r.pixel = parent.pixel;
        r.depth = uint16_t(parent.depth + 1);
        r.any_hit = true;
        r.shade = cos_theta;
        r.ray.origin = offset_ray_origin(sp, towards);
        if (s.at_infinity) {
            r.ray.direction = s.direction;
            r.ray.tmax = std::numeric_limits<float>::infinity();
        } else {
            r.ray.direction = s.point - r.ray.origin;
            r.ray.tmax = 1.0f - kShadowEpsilon;
        }
        if (ray_is_valid(r.ray)) out->push_back(r);
    }
}

PendingRay path_ray(const PendingRay& parent, RayKind kind, const SurfacePoint& sp, const Vec3& dir) {
    PendingRay r;
    r.kind = kind;
    r.pixel = parent.pixel;
    r.depth = uint16_t(parent.depth + 1);
    r.ray.origin = offset_ray_origin(sp, dir);
    r.ray.direction = dir;
    return r;
}

}  // namespace

void spawn_secondaries(const SpawnContext& ctx, const PendingRay& parent, const Hit& hit, uint64_t index,
                       std::vector<PendingRay>* out) {
    if (!hit.valid()) return;
    const Scene& scene = *ctx.scene;
    SurfacePoint sp = surface_point(scene, parent.ray, hit);
    const Material& m = scene.materials[sp.material];
    Rng rng(hash_combine(ctx.seed, parent.pixel, uint64_t(parent.depth) << 8 | uint64_t(parent.kind), index));
    Vec3 d = glm::normalize(parent.ray.direction);

    if (ctx.plan->wants(RayKind::shadow)) spawn_shadow_rays(ctx, parent, sp, rng, out);
    if (parent.depth >= ctx.bounces) return;
    // Past roulette_after bounces each path ray is spawned only if it survives (its own draw,
    // after the direction's, so traces without roulette keep their random numbers).
    const bool roulette = ctx.roulette_after > 0 && parent.depth >= ctx.roulette_after;
    auto survives = [&] { return !roulette || rng.next() < roulette_survival(m); };
    if (ctx.plan->wants(RayKind::reflection) && material_reflects(m)) {
        Vec3 r = glm::normalize(reflect(d, sp.normal));
        bool above = true;
        // glTF's GGX alpha is roughness squared; a perfectly smooth surface stays a mirror.
        const float alpha = m.roughness * m.roughness;
        if (ctx.glossy && alpha > 0.0f) {
            const float u1 = rng.next(), u2 = rng.next();
            above = ggx_reflect(d, sp.normal, std::max(alpha, 1e-4f), u1, u2, &r);
        }
        if (above && survives()) out->push_back(path_ray(parent, RayKind::reflection, sp, r));
    }
    if (ctx.plan->wants(RayKind::refraction) && material_refracts(m)) {
        Vec3 t;
        float eta_i = sp.front ? 1.0f : m.ior, eta_t = sp.front ? m.ior : 1.0f;
        if (refract(d, sp.normal, eta_i, eta_t, &t) && survives())
            out->push_back(path_ray(parent, RayKind::refraction, sp, t));
    }
    if (ctx.plan->wants(RayKind::diffuse)) {
        float u1 = rng.next(), u2 = rng.next();
        const Vec3 dir = cosine_hemisphere(sp.normal, u1, u2);
        if (survives()) out->push_back(path_ray(parent, RayKind::diffuse, sp, dir));
    }
}

float roulette_survival(const Material& m) {
    const float albedo = std::max(m.base_color.x, std::max(m.base_color.y, m.base_color.z));
    return std::min(0.95f, std::max(0.05f, albedo));
}

}  // namespace rtsim
