// Moving scenes (docs/accel.md, "Moving scenes"): a deforming mesh's BLAS per frame, built or
// refitted by the frame policy (frame_policy.h). Refitting changes work, never hits: every
// frame traces as a fresh build of its posed geometry; refitted trees bound their triangles;
// adaptive rebuilds once the refitted SAH cost crosses its threshold; kinds without a binary
// tree refuse to refit.
#include <cmath>

#include "accel_test_util.h"
#include "traces/accel/two_level/two_level.h"
#include "traces/bvh/refit.h"
#include "traces/common/error.h"
#include "traces/scene/scene.h"

namespace rtsim::test {
namespace {

/// Mesh 0 (a random soup) deforms: each triangle drifts rigidly in its own random direction by
/// `spread` per frame (scattering, which loosens a refitted tree) and the whole mesh waves; mesh
/// 1 stays still.
class DriftAnimation final : public MeshAnimation {
public:
    DriftAnimation(std::vector<Vec3> rest, float spread) : m_rest(std::move(rest)), m_spread(spread) {}
    bool deforms(uint32_t mesh) const override { return mesh == 0; }
    void pose(uint32_t, uint32_t frame, std::vector<Vec3>* out) const override {
        out->resize(m_rest.size());
        const float f = float(frame);
        for (size_t t = 0; t < m_rest.size() / 3; ++t) {
            const Vec3 c = (m_rest[3 * t] + m_rest[3 * t + 1] + m_rest[3 * t + 2]) / 3.0f;
            Rng rng(1000 + t);
            const Vec3 dir = random_point(rng, Vec3(-1.0f), Vec3(1.0f));
            const Vec3 move = m_spread * f * dir + Vec3(0.0f, 0.2f * std::sin(0.5f * f + c.x), 0.0f);
            for (int k = 0; k < 3; ++k) (*out)[3 * t + k] = m_rest[3 * t + k] + move;
        }
    }
    std::string description() const override { return "test drift"; }

private:
    std::vector<Vec3> m_rest;
    float m_spread;
};

Scene drift_scene(float spread) {
    Scene s;
    s.source = "frame policy test scene";
    s.materials = {Material{}};
    s.meshes = {soup_mesh(7, 300), soup_mesh(8, 50)};
    s.instances = {Instance{0, glm::dmat4(1.0), 0, -1}, Instance{1, glm::dmat4(1.0), 0, -1}};
    s.instances[1].object_to_world[3] = glm::dvec4(4.0, 0.0, 0.0, 1.0);
    s.animation = std::make_shared<DriftAnimation>(s.meshes[0].positions, spread);
    s.index_instances();
    return s;
}

AccelOptions two_level(const std::string& kind = "bvh2") {
    AccelOptions o;
    o.kind = kind;
    o.two_level = true;
    return o;
}

std::vector<std::vector<glm::dmat4>> still_poses(const Scene& s, uint32_t frames) {
    std::vector<glm::dmat4> pose;
    for (const Instance& i : s.instances) pose.push_back(i.object_to_world);
    return std::vector<std::vector<glm::dmat4>>(frames, pose);
}

/// The scene with its deforming mesh posed at `frame` and no animation: a fresh build's input.
Scene posed(const Scene& s, uint32_t frame) {
    Scene out = s;
    s.animation->pose(0, frame, &out.meshes[0].positions);
    out.animation = nullptr;
    out.index_instances();
    return out;
}

const nlohmann::json& build_of(const AccelImage& image, uint32_t frame) {
    return image.params.at("frames").at(frame).at("build");
}

TEST(FramePolicies, EveryFrameHitsAsAFreshBuildOfItsPose) {
    const Scene s = drift_scene(0.05f);
    const uint32_t frames = 6;
    for (FramePolicy p : {FramePolicy::rebuild, FramePolicy::refit, FramePolicy::adaptive}) {
        SCOPED_TRACE(frame_policy_name(p));
        const AccelImage image =
            build_two_level_frames(s, two_level(), still_poses(s, frames), nullptr, {s.animation.get(), {p, 1.1}});
        const std::unique_ptr<Accel> animated = load_accel(image, "frames");
        ASSERT_EQ(animated->frame_count(), frames);
        uint64_t refit_work = 0, fresh_work = 0;
        for (uint32_t f = 0; f < frames; ++f) {
            const Scene frame_scene = posed(s, f);
            const std::unique_ptr<Accel> fresh = load_accel(build_two_level(frame_scene, two_level()), "fresh");
            animated->bind_frame(f);
            Rng rng(30 + f);
            int hits = 0;
            for (int i = 0; i < 400; ++i) {
                const Ray r = random_ray(rng, frame_scene.bounds, nullptr, 0);
                for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
                    WorkCounts wa, wf;
                    const Hit a = animated->trace(r, mode, &wa), b = fresh->trace(r, mode, &wf);
                    if (mode == TraversalMode::closest_hit) {
                        ASSERT_TRUE(same_hit(a, b)) << "frame " << f << " ray " << i;
                        refit_work += wa.steps;
                        fresh_work += wf.steps;
                    } else {
                        ASSERT_EQ(a.valid(), b.valid()) << "frame " << f << " ray " << i;  // occlusion alike
                    }
                    hits += a.valid();
                }
            }
            EXPECT_GT(hits, 20) << "frame " << f;
            const std::string action = build_of(image, f)["blas"][0]["action"];
            if (f == 0 || p == FramePolicy::rebuild) EXPECT_EQ(action, "build");
            if (p == FramePolicy::refit && f > 0) EXPECT_EQ(action, "refit");
        }
        if (p == FramePolicy::rebuild) EXPECT_EQ(refit_work, fresh_work);  // the same trees
    }
}

TEST(FramePolicies, OrientedRefitsThatKeepTheirRotationsHitAsAFreshBuild) {
    const Scene s = drift_scene(0.1f);
    const uint32_t frames = 4;
    AccelOptions o = two_level("obvh2");
    o.settings = {{"obb_refit_keeps_rotations", true}, {"obb_min_gain", 0.0}};
    const AccelImage image =
        build_two_level_frames(s, o, still_poses(s, frames), nullptr, {s.animation.get(), {FramePolicy::refit, 1.1}});
    const std::unique_ptr<Accel> animated = load_accel(image, "frames");
    for (uint32_t f = 0; f < frames; ++f) {
        const Scene frame_scene = posed(s, f);
        AccelOptions fresh_options = two_level("obvh2");
        fresh_options.settings = {{"obb_min_gain", 0.0}};
        const std::unique_ptr<Accel> fresh = load_accel(build_two_level(frame_scene, fresh_options), "fresh");
        animated->bind_frame(f);
        Rng rng(60 + f);
        int hits = 0;
        for (int i = 0; i < 400; ++i) {
            const Ray r = random_ray(rng, frame_scene.bounds, nullptr, 0);
            WorkCounts wa, wf;
            const Hit a = animated->trace(r, TraversalMode::closest_hit, &wa);
            ASSERT_TRUE(same_hit(a, fresh->trace(r, TraversalMode::closest_hit, &wf))) << "frame " << f << " ray " << i;
            ASSERT_EQ(animated->trace(r, TraversalMode::any_hit, &wa).valid(), a.valid()) << "frame " << f;
            hits += a.valid();
        }
        EXPECT_GT(hits, 20) << "frame " << f;
    }
    // Each later frame's BLAS boxed its nodes only in their oriented ancestors' frames: fewer
    // node frames than the full fit's every node in every rotation of the table.
    const nlohmann::json& stats = image.stats.at("blas");
    int kept = 0;
    for (const nlohmann::json& b : stats) {
        const nlohmann::json& fit = b.at("obvh2");
        const uint64_t full = b.at("nodes").get<uint64_t>() * fit.at("rotations").get<uint64_t>();
        if (!fit.at("rotations_kept").get<bool>()) {
            EXPECT_EQ(fit.at("fit_node_frames").get<uint64_t>(), full);
            continue;
        }
        ++kept;
        EXPECT_GT(fit.at("fit_node_frames").get<uint64_t>(), 0u);
        EXPECT_LT(fit.at("fit_node_frames").get<uint64_t>(), full / 4);
    }
    EXPECT_EQ(kept, int(frames) - 1);
    // The policy weighs each frame's BLAS by its oriented boxes' SAH cost, which ages.
    for (uint32_t f = 0; f < frames; ++f) {
        const nlohmann::json& r = build_of(image, f)["blas"][0];
        EXPECT_DOUBLE_EQ(r["sah_cost"].get<double>(), stats.at(r["blas"].get<size_t>())["sah_cost"].get<double>());
        if (f > 0) EXPECT_GT(r["sah_ratio"].get<double>(), 1.0) << "frame " << f;
    }
}

TEST(FramePolicies, RefittedTreesBoundTheirTriangles) {
    const Scene s = drift_scene(0.2f);
    Scene a = posed(s, 0), b = posed(s, 5);
    a.flatten();
    b.flatten();
    const BuildTree built = build_binned_sah(a.triangles, BuildConfig{});
    const BuildTree refit = refit_build_tree(built, b.triangles);
    ASSERT_EQ(refit.nodes.size(), built.nodes.size());
    for (size_t i = 0; i < refit.nodes.size(); ++i) {
        const BuildNode& n = refit.nodes[i];
        if (n.is_leaf()) {
            for (uint32_t k = n.first; k < n.first + n.count; ++k) {
                const Triangle& t = b.triangles[refit.prim_ids[k]];
                for (const Vec3& v : {t.v0, t.v1, t.v2}) {
                    Aabb point;
                    point.grow(v);
                    EXPECT_TRUE(n.box.contains(point)) << "node " << i;
                }
            }
        } else {
            for (uint32_t c : {n.first, n.first + 1}) {
                EXPECT_TRUE(n.box.contains(refit.nodes[c].box)) << "node " << i;
            }
        }
        EXPECT_EQ(n.first, built.nodes[i].first);  // topology kept
        EXPECT_EQ(n.count, built.nodes[i].count);
    }
    // The drift loosens the refitted tree: its SAH cost grows past a rebuild's.
    const double refit_cost = sah_cost(refit, BuildConfig{});
    const double rebuilt_cost = sah_cost(build_binned_sah(b.triangles, BuildConfig{}), BuildConfig{});
    EXPECT_GT(refit_cost, rebuilt_cost);
    std::vector<Triangle> fewer(b.triangles.begin(), b.triangles.begin() + 10);
    EXPECT_THROW(refit_build_tree(built, fewer), Error);
}

TEST(FramePolicies, AdaptiveRebuildsOnceTheRefitCostCrossesItsThreshold) {
    const Scene s = drift_scene(0.3f);
    const uint32_t frames = 8;
    const AccelImage image = build_two_level_frames(s, two_level(), still_poses(s, frames), nullptr,
                                                    {s.animation.get(), {FramePolicy::adaptive, 1.2}});
    int rebuilds = 0;
    double last_ratio = 1.0;
    for (uint32_t f = 1; f < frames; ++f) {
        const nlohmann::json& b = build_of(image, f)["blas"][0];
        const bool rebuilt = b["action"] == "build";
        EXPECT_EQ(rebuilt, last_ratio > 1.2) << "frame " << f;  // decided by the previous frame's refit
        if (rebuilt) EXPECT_DOUBLE_EQ(b["sah_ratio"].get<double>(), 1.0);
        rebuilds += rebuilt;
        last_ratio = b["sah_ratio"];
    }
    EXPECT_GT(rebuilds, 0);
    EXPECT_LT(rebuilds, int(frames) - 1);
    // The static mesh's BLAS is built once; the deforming one's once per frame.
    EXPECT_EQ(image.params.at("blas").size(), 1u + frames);
}

TEST(FramePolicies, KindsWithoutABinaryTreeRefuseToRefit) {
    const Scene s = drift_scene(0.05f);
    const std::string msg = error_of([&] {
        build_two_level_frames(s, two_level("kdtree"), still_poses(s, 3), nullptr,
                               {s.animation.get(), {FramePolicy::refit, 1.25}});
    });
    EXPECT_NE(msg.find("rebuild"), std::string::npos) << msg;
    EXPECT_NO_THROW(build_two_level_frames(s, two_level("kdtree"), still_poses(s, 3), nullptr,
                                           {s.animation.get(), {FramePolicy::rebuild, 1.25}}));
    EXPECT_THROW(parse_frame_policy("sometimes"), Error);
}

}  // namespace
}  // namespace rtsim::test
