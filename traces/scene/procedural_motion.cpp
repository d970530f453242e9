// Analytic per-frame poses of the procedural deforming scenes, and their glTF extras encoding.
#include "traces/scene/procedural_motion.h"

#include <cmath>
#include <map>

#include <tiny_gltf.h>

#include "traces/common/error.h"
#include "traces/common/rng.h"
#include "traces/scene/scene.h"

namespace rtsim {

namespace {

constexpr const char* kKinds[] = {"wave", "scatter"};

struct Field {
    const char* key;
    float ProceduralMotion::*member;
};
const Field kFloats[] = {
    {"amplitude", &ProceduralMotion::amplitude}, {"wavelength", &ProceduralMotion::wavelength},
    {"period", &ProceduralMotion::period},       {"x_pinned", &ProceduralMotion::x_pinned},
    {"extent", &ProceduralMotion::extent},       {"speed_min", &ProceduralMotion::speed_min},
    {"speed_max", &ProceduralMotion::speed_max},
};

class ProceduralAnimation : public MeshAnimation {
public:
    struct Track {
        ProceduralMotion motion;
        std::vector<Vec3> rest;  ///< the mesh's positions at t = 0 (3 per triangle)
    };
    explicit ProceduralAnimation(std::map<uint32_t, Track> tracks) : m_tracks(std::move(tracks)) {}

    bool deforms(uint32_t mesh) const override { return m_tracks.count(mesh) != 0; }

    void pose(uint32_t mesh, uint32_t frame, std::vector<Vec3>* out) const override {
        auto it = m_tracks.find(mesh);
        if (it == m_tracks.end()) throw Error("procedural animation: mesh " + std::to_string(mesh) +
                                              " does not deform");
        const Track& track = it->second;
        const double t = double(frame) / frames_per_second();
        *out = track.rest;
        if (track.motion.kind == ProceduralMotion::Kind::wave) wave(track.motion, t, out);
        else scatter(track.motion, t, out);
    }

    std::string description() const override {
        std::string s = "procedural motion:";
        for (const auto& [mesh, track] : m_tracks)
            s += " mesh " + std::to_string(mesh) + " " + kKinds[int(track.motion.kind)];
        return s;
    }

private:
    static void wave(const ProceduralMotion& m, double t, std::vector<Vec3>* out) {
        const double two_pi = 6.283185307179586;
        for (Vec3& v : *out) {
            double ramp = std::max(0.0, double(v.x - m.x_pinned)) / double(m.extent);
            double phase = two_pi * (double(v.x) / m.wavelength - t / m.period);
            v.y += float(m.amplitude * ramp * std::sin(phase));
        }
    }

    static void scatter(const ProceduralMotion& m, double t, std::vector<Vec3>* out) {
        for (size_t tri = 0; tri * 3 + 2 < out->size(); ++tri) {
            Vec3* v = out->data() + tri * 3;
            Vec3 dir = (v[0] + v[1] + v[2]) / 3.0f - m.center;
            float len = glm::length(dir);
            // A triangle at the very centre goes up rather than nowhere.
            dir = len > 1e-6f ? dir / len : Vec3(0.0f, 1.0f, 0.0f);
            float u = hash_to_unit(hash_combine(m.seed, 0x73636174ull /*"scat"*/, tri));
            Vec3 offset = dir * float((m.speed_min + u * (m.speed_max - m.speed_min)) * t);
            for (int c = 0; c < 3; ++c) v[c] += offset;
        }
    }

    std::map<uint32_t, Track> m_tracks;
};

}  // namespace

tinygltf::Value procedural_motion_to_value(const ProceduralMotion& motion) {
    tinygltf::Value::Object o;
    o["kind"] = tinygltf::Value(std::string(kKinds[int(motion.kind)]));
    for (const Field& f : kFloats) o[f.key] = tinygltf::Value(double(motion.*f.member));
    o["center"] = tinygltf::Value(tinygltf::Value::Array{tinygltf::Value(double(motion.center.x)),
                                                         tinygltf::Value(double(motion.center.y)),
                                                         tinygltf::Value(double(motion.center.z))});
    o["seed"] = tinygltf::Value(int(motion.seed & 0x7fffffff));
    tinygltf::Value::Object extras;
    extras["rtsimMotion"] = tinygltf::Value(o);
    return tinygltf::Value(extras);
}

bool read_procedural_motion(const tinygltf::Value& extras, const std::string& where,
                            ProceduralMotion* out) {
    if (!extras.IsObject() || !extras.Has("rtsimMotion")) return false;
    const tinygltf::Value& o = extras.Get("rtsimMotion");
    auto fail = [&](const std::string& what) { throw Error(where + ": extras.rtsimMotion " + what); };
    if (!o.IsObject() || !o.Has("kind") || !o.Get("kind").IsString()) fail("has no string 'kind'");
    ProceduralMotion m;
    const std::string kind = o.Get("kind").Get<std::string>();
    if (kind == "wave") m.kind = ProceduralMotion::Kind::wave;
    else if (kind == "scatter") m.kind = ProceduralMotion::Kind::scatter;
    else fail("kind '" + kind + "' unknown (known: wave, scatter)");
    auto number = [&](const tinygltf::Value& v, const std::string& key) {
        if (!v.IsNumber() || !std::isfinite(v.GetNumberAsDouble())) fail("'" + key + "' is not a finite number");
        return v.GetNumberAsDouble();
    };
    for (const Field& f : kFloats)
        if (o.Has(f.key)) m.*f.member = float(number(o.Get(f.key), f.key));
    if (o.Has("center")) {
        const tinygltf::Value& c = o.Get("center");
        if (!c.IsArray() || c.ArrayLen() != 3) fail("'center' is not 3 numbers");
        m.center = Vec3(float(number(c.Get(0), "center")), float(number(c.Get(1), "center")),
                        float(number(c.Get(2), "center")));
    }
    if (o.Has("seed")) m.seed = uint64_t(number(o.Get("seed"), "seed"));
    if (m.kind == ProceduralMotion::Kind::wave && (!(m.wavelength > 0) || !(m.period > 0) || !(m.extent > 0)))
        fail("wave needs wavelength, period and extent > 0");
    *out = m;
    return true;
}

std::shared_ptr<const MeshAnimation> make_procedural_animation(
    const Scene& scene, std::vector<std::pair<uint32_t, ProceduralMotion>> motions) {
    std::map<uint32_t, ProceduralAnimation::Track> tracks;
    for (auto& [mesh, motion] : motions) tracks[mesh] = {motion, scene.meshes.at(mesh).positions};
    return std::make_shared<ProceduralAnimation>(std::move(tracks));
}

}  // namespace rtsim
