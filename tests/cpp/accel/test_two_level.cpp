// Two-level structures (traces/accel/two_level): hits through instances equal the flattened
// scene's, for BLASes of several kinds and transforms with rotation, non-uniform scale, mirror
// and nested hierarchies; the image validates and refuses corruption; the partition covers
// every key.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>

#include <glm/gtc/matrix_transform.hpp>

#include "accel_test_util.h"
#include "structure_test_util.h"
#include "traces/accel/two_level/two_level.h"
#include "traces/scene/gltf_loader.h"
#include "traces/scene/scene.h"

namespace rtsim::test {
namespace {

/// A closed UV sphere of radius 1 (so rays through shared edges must not leak).
Mesh sphere_mesh(int stacks, int slices) {
    Mesh m;
    m.name = "sphere";
    auto p = [&](int i, int j) {
        const double th = M_PI * i / stacks, ph = 2.0 * M_PI * (j % slices) / slices;
        return Vec3(float(std::sin(th) * std::cos(ph)), float(std::cos(th)), float(std::sin(th) * std::sin(ph)));
    };
    for (int i = 0; i < stacks; ++i)
        for (int j = 0; j < slices; ++j) {
            const Vec3 a = p(i, j), b = p(i + 1, j), c = p(i + 1, j + 1), d = p(i, j + 1);
            if (i > 0) m.positions.insert(m.positions.end(), {a, b, d});
            if (i + 1 < stacks) m.positions.insert(m.positions.end(), {b, c, d});
        }
    m.materials.assign(m.positions.size() / 3, 0);
    return m;
}

/// Instances of two meshes on a grid: rotations, non-uniform scales, mirrors (negative
/// determinant), each under a parent transform as a nested node hierarchy composes it.
Scene instanced_scene(int per_side) {
    Scene s;
    s.source = "instanced test scene";
    s.materials = {Material{}};
    s.meshes = {sphere_mesh(12, 16), soup_mesh(7, 60)};
    const glm::dmat4 parent = glm::rotate(glm::translate(glm::dmat4(1.0), glm::dvec3(0.5, -1.0, 2.0)), 0.3,
                                          glm::dvec3(0.0, 1.0, 0.0));
    uint32_t prim = 0;
    for (int i = 0; i < per_side; ++i)
        for (int j = 0; j < per_side; ++j) {
            const uint32_t mesh = (i + j) % 2;
            glm::dmat4 m = glm::translate(parent, glm::dvec3(3.0 * i, 0.4 * j, 3.0 * j));
            m = glm::rotate(m, 0.7 * i + 0.2 * j, glm::normalize(glm::dvec3(1.0, 2.0, 0.5 + j)));
            m = glm::scale(m, glm::dvec3(1.0 + 0.5 * i, 0.6 + 0.1 * j, (i + j) % 3 == 0 ? -1.3 : 0.9));
            s.instances.push_back(Instance{mesh, m, prim, -1});
            prim += uint32_t(s.meshes[mesh].triangle_count());
        }
    s.flatten();
    return s;
}

std::unique_ptr<Accel> two_level(const Scene& scene, const std::string& blas_kind) {
    AccelOptions o;
    o.kind = blas_kind;
    o.two_level = true;
    return load_accel(build_accel(scene, o), "two-level " + blas_kind);
}

/// Rays aimed at a point inside a triangle of the flattened scene, plus random rays, compared
/// with the flattened BVH's hits. The object-space triangle test rounds differently from the
/// world-space one, so a ray through an edge or vertex may hit the neighbour or slip past a
/// silhouette (docs/accel.md, "Two-level structures"); the classes are docs/validation.md's.
struct Disagreement {
    int edge = 0;   ///< a hit that only one side reports lies within 1e-4 (barycentric) of an edge
    int other = 0;  ///< anything else: must be 0
};

bool near_edge(const Hit& h) { return h.valid() && std::min({h.u, h.v, 1.0f - h.u - h.v}) < 1e-4f; }

/// The two hit points of one primitive agree along its normal to 2^-16 of the scene's size (the
/// vertices and the object-space ray are each rounded once; t itself is ill-conditioned for
/// grazing rays, so it is compared through the distance it puts the point off the plane).
bool same_point(const Scene& scene, const Ray& r, const Hit& f, const Hit& h) {
    const Triangle& tri = scene.triangles[uint32_t(f.prim)];
    const Vec3 n = glm::normalize(glm::cross(tri.v1 - tri.v0, tri.v2 - tri.v0));
    const float off_plane = std::fabs(f.t - h.t) * std::fabs(glm::dot(n, r.direction));
    float size = 0.0f;
    for (int a = 0; a < 3; ++a) size = std::max({size, std::fabs(scene.bounds.lo[a]), std::fabs(scene.bounds.hi[a])});
    return off_plane <= size * 0x1p-16f;
}

Disagreement compare(const Scene& scene, const Accel& flat, const Accel& two, TraversalMode mode, int rays) {
    Rng rng(42);
    Disagreement d;
    for (int i = 0; i < rays; ++i) {
        Ray r = random_ray(rng, scene.bounds, nullptr, 0);
        const bool aimed = i % 2 == 0;
        if (aimed) {
            const Triangle& t = scene.triangles[uint64_t(rng.next() * float(scene.triangle_count())) % scene.triangle_count()];
            const float a = 0.2f + 0.3f * rng.next(), b = 0.2f + 0.3f * rng.next() * (1.0f - a);
            r.direction = t.v0 + a * (t.v1 - t.v0) + b * (t.v2 - t.v0) - r.origin;
            r.tmin = 0.0f;
            r.tmax = std::numeric_limits<float>::infinity();
        }
        WorkCounts wf, wt;
        const Hit f = flat.trace(r, mode, &wf), h = two.trace(r, mode, &wt);
        bool same = f.valid() == h.valid();
        if (same && f.valid() && mode == TraversalMode::closest_hit)
            same = f.prim == h.prim && f.inst == h.inst && same_point(scene, r, f, h);
        if (same) continue;
        if (near_edge(f) || near_edge(h)) {
            ++d.edge;
            continue;
        }
        ++d.other;
        ADD_FAILURE() << "ray " << i << (aimed ? " (aimed)" : "") << ": flattened prim " << f.prim << " inst " << f.inst
                      << " t " << f.t << " u " << f.u << " v " << f.v << "; two-level prim " << h.prim << " inst "
                      << h.inst << " t " << h.t << " u " << h.u << " v " << h.v;
        if (h.valid()) {
            EXPECT_GT(wt.transforms, 0u);
        }
    }
    return d;
}

TEST(TwoLevel, HitsEqualFlattenedForEveryBlasKind) {
    const Scene scene = instanced_scene(6);
    const std::unique_ptr<Accel> flat = build_kind(scene, "bvh2");
    for (const char* kind : {"bvh2", "bvh8", "cwbvh8", "grid"}) {
        SCOPED_TRACE(kind);
        const std::unique_ptr<Accel> two = two_level(scene, kind);
        for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
            const Disagreement d = compare(scene, *flat, *two, mode, 4000);
            EXPECT_EQ(d.other, 0);
            EXPECT_LE(d.edge, 8) << "of 4000 rays";
        }
    }
}

TEST(TwoLevel, SharedInstancedScenesHitAsFlattened) {
    for (const char* name : {"SimpleInstancing", "MetalRoughSpheresNoTextures"}) {
        SCOPED_TRACE(name);
        const std::string path = std::string(RTSIM_SCENES_DIR) + "/" + name + "/" + name + ".gltf";
        if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not found";
        const Scene scene = load_gltf(path);
        ASSERT_TRUE(shares_geometry(scene));
        const std::unique_ptr<Accel> flat = build_kind(scene, "bvh2");
        for (const char* kind : {"bvh2", "bvh8"}) {
            const std::unique_ptr<Accel> two = two_level(scene, kind);
            for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
                const Disagreement d = compare(scene, *flat, *two, mode, 4000);
                EXPECT_EQ(d.other, 0) << kind;
                EXPECT_LE(d.edge, 8) << kind << ": of 4000 rays";
            }
        }
    }
}

TEST(TwoLevel, InstanceAndGlobalPrimitiveIdsAndWorldT) {
    const Scene scene = instanced_scene(3);
    const std::unique_ptr<Accel> two = two_level(scene, "bvh2");
    for (size_t k = 0; k < scene.instances.size(); ++k) {
        // A ray straight at the middle of each instance's first triangle.
        const Triangle& t = scene.triangles[scene.instances[k].prim_base];
        const Vec3 target = (t.v0 + t.v1 + t.v2) / 3.0f;
        Ray r;
        r.origin = target + Vec3(0.0f, 20.0f, 0.0f) + Vec3(0.01f * float(k), 0.0f, 0.0f);
        r.direction = target - r.origin;
        const Hit h = two->trace(r, TraversalMode::closest_hit);
        ASSERT_TRUE(h.valid());
        EXPECT_EQ(uint32_t(h.inst), scene.tri_instance[uint32_t(h.prim)]);
        EXPECT_LE(h.t, 1.0f + 1e-5f);  // world t: the target is at t = 1 unless something is nearer
    }
}

TEST(TwoLevel, StackOpsAndPartition) {
    const Scene scene = instanced_scene(4);
    const std::unique_ptr<Accel> two = two_level(scene, "bvh8");
    const auto kinds = two->op_kinds();
    EXPECT_NE(std::find(kinds.begin(), kinds.end(), OpKind::transform), kinds.end());
    EXPECT_GT(two->max_stack_entries(), 64u);
    const LocalityPartition p = two->partition(4096);
    for (uint32_t g : p.group_of) EXPECT_LT(g, p.treelets.size());
    // Every step's locality key is a key of the partition.
    std::unique_ptr<Stepper> s = two->make_stepper();
    Rng rng(3);
    for (int i = 0; i < 200; ++i) {
        s->begin(random_ray(rng, scene.bounds, nullptr, 0), TraversalMode::closest_hit);
        for (; !s->done(); s->execute())
            if (s->plan().locality != kNoLocality) {
                EXPECT_LT(s->plan().locality, p.group_of.size());
            }
    }
}

TEST(TwoLevel, UnflattenedSceneGivesTheFlattenedTrianglesAndTheSameStructure) {
    const Scene flat = instanced_scene(3);
    Scene kept = flat;
    kept.index_instances();
    ASSERT_FALSE(kept.flattened());
    EXPECT_EQ(kept.triangle_count(), flat.triangle_count());
    EXPECT_TRUE(kept.bounds.contains(flat.bounds));
    for (uint32_t prim = 0; prim < flat.triangle_count(); ++prim) {
        const Triangle a = kept.world_triangle(prim), &b = flat.triangles[prim];
        ASSERT_TRUE(a.v0 == b.v0 && a.v1 == b.v1 && a.v2 == b.v2) << prim;
        ASSERT_EQ(kept.instance_of(prim), flat.tri_instance[prim]) << prim;
        ASSERT_EQ(kept.material_of(prim), flat.tri_material[prim]) << prim;
    }
    AccelOptions o;
    o.two_level = true;
    AccelImage a = build_accel(flat, o), b = build_accel(kept, o);
    ASSERT_EQ(a.regions.size(), b.regions.size());
    for (size_t r = 0; r < a.regions.size(); ++r)
        EXPECT_EQ(std::memcmp(a.regions[r].bytes.data(), b.regions[r].bytes.data(), a.regions[r].size_bytes()), 0)
            << a.regions[r].name;
}

TEST(TwoLevel, PerLevelTrailsReducedPrecisionBlasesAndCompressedLeavesKeepHitsAndWork) {
    // Restart trails per level, reduced-precision BLAS boxes and compressed BLAS leaves change no
    // hit and no reference work (their work is the model's own fields); a one-entry short stack
    // restarts, and the narrower boxes enter extra subtrees.
    const Scene scene = instanced_scene(4);
    const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), 41, 800);
    for (const std::string blas : {"bvh2", "bvh4", "cwbvh8"}) {
        const std::unique_ptr<Accel> plain = two_level(scene, blas);
        AccelOptions o;
        o.kind = blas;
        o.two_level = true;
        o.settings["compressed_leaves"] = true;
        const std::unique_ptr<Accel> packed = load_accel(build_accel(scene, o), "compressed two-level " + blas);
        ASSERT_TRUE(packed->image().has_region(std::string("blas_") + kLeafBlocksRegion)) << blas;
        const AccelCapabilities caps = plain->capabilities();
        EXPECT_TRUE(caps.restart_trail && caps.reduced_precision_boxes && caps.compressed_leaves) << blas;
        StepOptions trail, rp;
        trail.short_stack_entries = 1;
        rp.box_precision_bits = 7;
        uint64_t restarts = 0, rp_steps = 0;
        int diffs = 0;
        for (const Ray& r : rays)
            for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
                WorkCounts want, got, got_rp, got_packed;
                const Hit h = plain->trace(r, mode, &want);
                const Hit ht = plain->trace(r, mode, &got, trail);
                const Hit hr = plain->trace(r, mode, &got_rp, rp);
                const Hit hp = packed->trace(r, mode, &got_packed);
                const bool ok = test::same_hit(ht, h, mode) && test::same_hit(hr, h, mode) &&
                                test::same_hit(hp, h, mode) && got.traced() == want.traced() &&
                                got_rp.traced() == want.traced() && got_packed == want;
                if (!ok && ++diffs <= 3) ADD_FAILURE() << blas << ": ray differs, prim " << h.prim;
                restarts += got.restarts;
                rp_steps += got_rp.rp_steps + got_rp.rp_box_hits;
            }
        EXPECT_EQ(diffs, 0) << blas;
        EXPECT_GT(restarts, 0u) << blas;
        EXPECT_GT(rp_steps, 0u) << blas;
    }
}

TEST(TwoLevel, AnyHitOrdersAtBothLevelsKeepOcclusionAndChangeTheWalk) {
    // traversal.anyhit_order at the TLAS's nodes and the BLASes': occlusion never changes,
    // closest-hit rays keep hit and work, plans ask for the work counted; a shadow packet of
    // copies of one ray does that ray's reordered work (the boxes' order is every ray's).
    const Scene scene = instanced_scene(4);
    const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), 43, 800);
    for (const std::string blas : {"bvh2", "bvh8", "cwbvh8"}) {
        const std::unique_ptr<Accel> accel = two_level(scene, blas);
        ASSERT_TRUE(accel->capabilities().anyhit_order) << blas;
        for (AnyHitOrder order : {AnyHitOrder::largest_box, AnyHitOrder::fixed}) {
            StepOptions options;
            options.anyhit_order = order;
            std::unique_ptr<Stepper> ordered = accel->make_stepper(options);
            int diffs = 0, walked_otherwise = 0;
            for (const Ray& r : rays)
                for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
                    WorkCounts want;
                    const Hit h = accel->trace(r, mode, &want);
                    const WorkCounts planned = test::tally_plans(*ordered, r, mode);
                    const WorkCounts got = ordered->work();
                    // The plans' tests (a plan counts no TLAS share or transform fields).
                    bool ok = test::same_hit(ordered->hit(), h, mode) && planned.box_tests == got.box_tests &&
                              planned.tri_tests == got.tri_tests;
                    if (mode == TraversalMode::closest_hit) ok = ok && got == want;
                    else walked_otherwise += got.steps != want.steps;
                    if (!ok && ++diffs <= 3)
                        ADD_FAILURE() << blas << " order " << int(order) << ": ray differs: hit " << ordered->hit().prim
                                      << "/" << h.prim << " steps " << got.steps << "/" << want.steps;
                }
            EXPECT_EQ(diffs, 0) << blas;
            EXPECT_GT(walked_otherwise, 0) << blas << ": the order changed no walk";
            for (size_t i = 0; i < 64; ++i) {
                if (!ray_is_valid(rays[i])) continue;
                WorkCounts single;
                accel->trace(rays[i], TraversalMode::any_hit, &single, options);
                const std::vector<Ray> same(16, rays[i]);
                const std::vector<TraversalMode> modes(16, TraversalMode::any_hit);
                std::vector<WorkCounts> work(16);
                accel->trace_packet(same.data(), modes.data(), 16, nullptr, work.data(), nullptr, 0.0f, options);
                for (const WorkCounts& w : work) EXPECT_EQ(w, single) << blas << " ray " << i;
            }
        }
    }
}

TEST(TwoLevel, PacketsSplitInsideInstancesKeepHitsAndAgreeWithTheReferenceLoop) {
    // The hybrid on two levels: BLAS packets split below the fraction, their rays finish the
    // instance alone; hits stay the single-ray walk's, the stepper's work and counts are the
    // reference packet loop's, and random rays split.
    const Scene scene = instanced_scene(4);
    const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), 47, 640);
    for (const std::string blas : {"bvh2", "cwbvh8"}) {
        const std::unique_ptr<Accel> accel = two_level(scene, blas);
        std::unique_ptr<PacketStepper> s = accel->make_packet_stepper();
        s->set_split_below(0.5f);
        uint64_t splits = 0;
        int diffs = 0;
        for (size_t first = 0; first + 16 <= rays.size(); first += 16)
            for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
                const std::vector<TraversalMode> modes(16, mode);
                std::vector<Hit> hits(16);
                std::vector<WorkCounts> work(16);
                PacketCounts fused;
                accel->trace_packet(&rays[first], modes.data(), 16, hits.data(), work.data(), &fused, 0.5f);
                s->begin_packet(&rays[first], modes.data(), 16);
                while (!s->done()) s->execute();
                EXPECT_EQ(s->counts(), fused) << blas;
                splits += fused.splits;
                for (uint32_t i = 0; i < 16; ++i) {
                    EXPECT_EQ(s->lane_work(i), work[i]) << blas;
                    if (!test::same_hit(hits[i], accel->trace(rays[first + i], mode), mode) && ++diffs <= 3)
                        ADD_FAILURE() << blas << ": ray " << first + i << " differs from its single-ray walk";
                }
            }
        EXPECT_EQ(diffs, 0) << blas;
        EXPECT_GT(splits, 0u) << blas;
    }
}

TEST(TwoLevel, ValidationRefusesBadInstanceRecords) {
    const Scene scene = instanced_scene(2);
    AccelOptions o;
    o.two_level = true;
    AccelImage image = build_accel(scene, o);
    image.region("instances").records<InstanceRecord>()[1].blas = 99;
    try {
        load_accel(std::move(image), "corrupt");
        FAIL() << "accepted a record naming a missing BLAS";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("instance record 1"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace rtsim::test
