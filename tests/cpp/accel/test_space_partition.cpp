// The space-partitioning structures (kd-tree, BIH from its three builders, octree) and the LBVH
// builder: layout invariants, hits identical to brute force and to the binary BVH on random soups
// and every procedural scene (closest and any hit), the fused loop equal to the stepper and to
// its plans on every ray, and the numerically hard cases with zero false misses: rays along the
// structures' own split planes, along cube faces and edges, through vertices, axis-parallel rays
// (+-0 components), huge and tiny coordinates, degenerate triangles.
#include <gtest/gtest.h>

#include "space_partition_util.h"
#include "traces/accel/bih/bih.h"
#include "traces/accel/bkd/bkd.h"
#include "traces/accel/kdtree/kdtree.h"
#include "traces/accel/octree/octree.h"
#include "traces/bvh/builder.h"
#include "traces/bvh/lbvh_builder.h"
#include "traces/scene/procedural.h"

namespace rtsim {
namespace {

using test::build_named;
using test::expect_structure_correct;

TEST(SpacePartition, LayoutInvariantsOnRandomSoups) {
    for (uint64_t seed : {1, 2}) {
        const Scene scene = test::random_soup(seed, 1500);
        const auto kd = build_named(scene, "kdtree");
        EXPECT_NO_THROW(check_kdtree_invariants(static_cast<const KdAccel&>(*kd).view(), scene));
        for (const char* name : {"bih", "bih:wachter_keller", "bih:lbvh"}) {
            const auto bih = build_named(scene, name);
            EXPECT_NO_THROW(check_bih_invariants(static_cast<const BihAccel&>(*bih).view(), scene)) << name;
        }
        const auto oct = build_named(scene, "octree");
        EXPECT_NO_THROW(check_octree_invariants(static_cast<const OctreeAccel&>(*oct).view(), scene));
        // Without clipping the kd-tree and the octree list more references, still correctly.
        const auto kd_boxes = build_named(scene, "kdtree", {{"clip", false}});
        EXPECT_NO_THROW(check_kdtree_invariants(static_cast<const KdAccel&>(*kd_boxes).view(), scene));
        EXPECT_GE(kd_boxes->image().stats["references"].get<uint64_t>(), kd->image().stats["references"].get<uint64_t>());
        const auto oct_boxes = build_named(scene, "octree", {{"clip", false}});
        EXPECT_NO_THROW(check_octree_invariants(static_cast<const OctreeAccel&>(*oct_boxes).view(), scene));
    }
    // LBVH trees keep the binary BVH's invariants.
    const Scene scene = test::random_soup(3, 2000);
    BuildConfig c;
    const BuildTree tree = build_lbvh(scene.triangles, c);
    EXPECT_NO_THROW(check_bvh_invariants(flatten_bvh(tree, scene, c), scene));
}

TEST(SpacePartition, HitsEqualBruteForceAndBvh2OnRandomSoups) {
    for (uint64_t seed : {4, 5}) {
        const Scene scene = test::random_soup(seed, 1200);
        const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), seed, 2500);
        for (const std::string& name : test::partition_kinds())
            EXPECT_GT(expect_structure_correct(*build_named(scene, name), scene, rays, name), 200) << name;
        // The settings that shape these trees, at their ends.
        for (const auto& [name, settings] : std::vector<std::pair<std::string, nlohmann::json>>{
                 {"kdtree", {{"empty_bonus", 0.0}, {"max_depth", 4}}},
                 {"kdtree", {{"traversal_cost", 1.0}, {"intersection_cost", 80.0}, {"clip", false}}},
                 {"octree", {{"max_leaf_size", 2}, {"max_depth", 10}}},
                 {"octree", {{"max_depth", 1}}},
                 {"bih:wachter_keller", {{"max_leaf_size", 1}}},
                 {"bvh2:lbvh", {{"morton_bits", 2}, {"max_leaf_size", 1}}}})
            expect_structure_correct(*build_named(scene, name, settings), scene, rays, name + " " + settings.dump());
    }
}

TEST(SpacePartition, HitsEqualOnEveryProceduralScene) {
    for (const std::string& name : procedural_scene_names()) {
        const Scene& scene = test::procedural(name);
        const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), 7, 600);
        for (const std::string& kind : test::partition_kinds())
            expect_structure_correct(*build_named(scene, kind), scene, rays, name + " " + kind);
    }
}

/// Rays in the planes a structure cuts space with, from the image's own planes: along them (in
/// the plane, axis-parallel and diagonal), across them and through their crossings.
std::vector<Ray> rays_in_planes(const std::vector<std::pair<int, float>>& planes, const Aabb& b, uint64_t seed) {
    Rng rng(seed);
    std::vector<Ray> rays;
    const Vec3 extent = b.hi - b.lo;
    for (size_t i = 0; i < planes.size() && rays.size() < 4000; i += 1 + planes.size() / 500) {
        const auto [axis, p] = planes[i];
        Vec3 o = test::random_point(rng, b.lo - 0.1f * extent, b.hi + 0.1f * extent);
        o[axis] = p;
        for (int k = 0; k < 4; ++k) {
            Vec3 d = test::random_direction(rng);
            d[axis] = k == 0 ? 0.0f : k == 1 ? -0.0f : d[axis];  // lying in the plane, or crossing it
            if (k == 3) d = Vec3(0.0f), d[(axis + 1) % 3] = 1.0f;  // axis-parallel, in the plane
            rays.push_back(test::make_ray(o, d));
            rays.push_back(test::make_ray(o - 2.0f * d, d));  // starting outside, entering in it
        }
    }
    return rays;
}

std::vector<std::pair<int, float>> split_planes(const Accel& a) {
    std::vector<std::pair<int, float>> planes;
    if (const auto* kd = dynamic_cast<const KdAccel*>(&a)) {
        for (uint64_t i = 0; i < kd->view().node_count; ++i)
            if (!kd->view().nodes[i].leaf()) planes.push_back({kd->view().nodes[i].axis(), kd->view().nodes[i].split()});
    } else if (const auto* bih = dynamic_cast<const BihAccel*>(&a)) {
        for (uint64_t i = 0; i < bih->view().node_count; ++i) {
            const BihNode& n = bih->view().nodes[i];
            if (!n.leaf()) planes.insert(planes.end(), {{n.axis(), n.clip(0)}, {n.axis(), n.clip(1)}});
        }
    } else if (const auto* bkd = dynamic_cast<const BkdAccel*>(&a)) {
        for (uint64_t i = 0; i < bkd->view().node_count; ++i) {
            const BkdNode& n = bkd->view().nodes[i];
            if (!n.leaf())
                for (int p = 0; p < 4; ++p) planes.push_back({n.axis(), n.bound(p / 2, p % 2)});
        }
    } else if (const auto* oct = dynamic_cast<const OctreeAccel*>(&a)) {
        for (uint64_t i = 0; i < oct->view().node_count; ++i)
            if (!oct->view().nodes[i].leaf())
                for (int axis = 0; axis < 3; ++axis) planes.push_back({axis, oct->view().nodes[i].centre(axis)});
    }
    return planes;
}

TEST(SpacePartitionHardCases, RaysInTheStructuresOwnPlanes) {
    for (const char* scene_name : {"soup", "cornell", "rotated_walls"}) {
        const Scene soup = test::random_soup(8, 800);
        const Scene& scene = std::string(scene_name) == "soup" ? soup : test::procedural(scene_name);
        for (const char* name : {"kdtree", "bih", "bih:wachter_keller", "octree", "bkd", "bkd:median"}) {
            const auto a = build_named(scene, name);
            const std::vector<std::pair<int, float>> planes = split_planes(*a);
            ASSERT_FALSE(planes.empty()) << name;
            expect_structure_correct(*a, scene, rays_in_planes(planes, a->image().bounds, 9), std::string(scene_name) + " " + name);
        }
    }
}

TEST(SpacePartitionHardCases, FacesEdgesVerticesAndScales) {
    const std::vector<Vec3> unit = test::tessellated_cube(8);
    for (const auto& [scale, offset] : std::vector<std::pair<float, float>>{{1.0f, 0.0f}, {1e12f, 0.0f}, {1e-12f, 0.0f},
                                                                          {1.0f, 1e6f}, {3e10f, -7e11f}}) {
        std::vector<Vec3> soup;
        for (const Vec3& v : unit) soup.push_back(Vec3(offset) + scale * v);
        const Scene scene = test::make_scene(soup);
        const std::string what = "cube x " + std::to_string(scale) + " + " + std::to_string(offset);
        for (const std::string& name : test::partition_kinds())
            EXPECT_GT(expect_structure_correct(*build_named(scene, name), scene, test::lattice_rays(scale, Vec3(offset)),
                                               what + " " + name),
                      500)
                << what << " " << name;
    }
}

TEST(SpacePartitionHardCases, DegenerateTrianglesAndFlatScenes) {
    std::vector<Vec3> soup;
    Rng rng(5);
    for (int i = 0; i < 400; ++i) {
        const Vec3 c = (i % 2 ? Vec3(100.0f) : Vec3(0.0f)) + test::random_point(rng, Vec3(0.0f), Vec3(2.0f));
        Vec3 p[3] = {c, c + test::random_point(rng, Vec3(-0.3f), Vec3(0.3f)), c + test::random_point(rng, Vec3(-0.3f), Vec3(0.3f))};
        if (i % 7 == 0) p[2] = p[1];                  // repeated vertex
        if (i % 11 == 0) p[2] = 2.0f * p[1] - p[0];  // collinear
        if (i % 13 == 0) p[1] = p[2] = p[0];          // a point
        soup.insert(soup.end(), {p[0], p[1], p[2]});
    }
    const Scene clusters = test::make_scene(soup);
    // A flat scene: every triangle in z = 0.5 (the octree does not cut z, the kd-tree cannot).
    std::vector<Vec3> flat;
    for (int i = 0; i < 300; ++i) {
        const Vec3 c(test::random_point(rng, Vec3(-3.0f), Vec3(3.0f)));
        for (int k = 0; k < 3; ++k) {
            Vec3 v = c + 0.4f * test::random_point(rng, Vec3(-1.0f), Vec3(1.0f));
            v.z = 0.5f;
            flat.push_back(v);
        }
    }
    const Scene flat_scene = test::make_scene(flat);
    for (const std::string& name : test::partition_kinds()) {
        expect_structure_correct(*build_named(clusters, name), clusters,
                                 test::random_rays(clusters, test::hw_triangles(clusters), 9, 3000), "clusters " + name);
        std::vector<Ray> rays = test::random_rays(flat_scene, test::hw_triangles(flat_scene), 10, 2000);
        for (const Ray& r : test::lattice_rays(2.0f, Vec3(0.0f, 0.0f, 0.5f))) rays.push_back(r);
        EXPECT_GT(expect_structure_correct(*build_named(flat_scene, name), flat_scene, rays, "flat " + name), 100) << name;
    }
}

}  // namespace
}  // namespace rtsim
