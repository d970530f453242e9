#include "traces/common/rng.h"

#include <cmath>
#include <cstring>

#include "traces/common/error.h"
#include "traces/common/ray.h"

namespace rtsim {

uint64_t mix64(uint64_t x) {
    x ^= x >> 30;
    x *= 0xBF58476D1CE4E5B9ull;
    x ^= x >> 27;
    x *= 0x94D049BB133111EBull;
    x ^= x >> 31;
    return x;
}

uint64_t hash_combine(uint64_t seed, uint64_t a, uint64_t b, uint64_t c) {
    uint64_t h = mix64(seed + 0x9E3779B97F4A7C15ull);
    h = mix64(h ^ (a + 0x632BE59BD9B4E019ull));
    h = mix64(h ^ (b + 0x8CB92BA72F3D8DD7ull));
    return mix64(h ^ (c + 0xD6E8FEB86659FD93ull));
}

float hash_to_unit(uint64_t h) { return float(h >> 40) * (1.0f / 16777216.0f); }

const char* ray_kind_name(RayKind kind) {
    switch (kind) {
        case RayKind::primary: return "primary";
        case RayKind::shadow: return "shadow";
        case RayKind::reflection: return "reflection";
        case RayKind::diffuse: return "diffuse";
        case RayKind::refraction: return "refraction";
    }
    return "unknown";
}

RayKind parse_ray_kind(const char* text) {
    for (int k = 0; k < kRayKindCount; ++k)
        if (std::strcmp(text, ray_kind_name(RayKind(k))) == 0) return RayKind(k);
    throw Error(std::string("unknown ray kind '") + text +
                "' (expected primary, shadow, reflection, diffuse or refraction)");
}

bool ray_is_valid(const Ray& r) {
    auto finite = [](const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
    if (!finite(r.origin) || !finite(r.direction)) return false;
    if (r.direction.x == 0.0f && r.direction.y == 0.0f && r.direction.z == 0.0f) return false;
    if (std::isnan(r.tmin) || std::isnan(r.tmax) || r.tmin > r.tmax) return false;
    return !std::isinf(r.tmin);
}

}  // namespace rtsim
