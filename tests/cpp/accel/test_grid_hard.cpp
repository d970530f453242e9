// The uniform grid on the numerically hard cases (rays along cell faces and through cell
// corners, axis-parallel rays, origins inside, outside and on the bounds, huge and tiny
// coordinates, degenerate triangles, empty scenes and cells): zero false misses and hits
// identical to brute force. Then validation refusing corrupt images by name, the registry and
// the trace file, and bricks.
#include <gtest/gtest.h>

#include <filesystem>

#include "tests/cpp/error_of.h"
#include "structure_test_util.h"
#include "traces/accel/accel_io.h"
#include "traces/accel/bvh2/bvh2.h"
#include "traces/accel/grid/grid.h"
#include "traces/common/error.h"
#include "tests/cpp/process_temp_dir.h"

namespace rtsim {
namespace {

using test::error_of;

/// Zero differences against brute force (closest: bits; any: hit or miss).
void expect_brute(const Scene& scene, const GridConfig& config, const std::vector<Ray>& rays, const std::string& what,
                  int min_hits) {
    const std::unique_ptr<Accel> g = load_accel(grid_image(scene, config), what);
    const std::vector<HwTriangle> tris = test::hw_triangles(scene);
    const test::Agreement ag = test::compare_rays(test::tracer(*g), test::brute_force(tris), rays, what);
    EXPECT_EQ(ag.diffs, 0) << what;
    EXPECT_GE(ag.hits, min_hits) << what;
}

TEST(GridHardCases, RaysAlongCellFacesAndThroughCorners) {
    // 8 x 8 cells per face on a cube whose grid is 8^3 cells of 0.25: every vertex on a plane.
    const Scene cube = test::make_scene(test::tessellated_cube(8));
    GridConfig c;
    c.density = 2.0f / 3.0f;  // 512 cells for 768 triangles
    const AccelImage image = grid_image(cube, c);
    const GridGeometry g = GridGeometry::from_json(image.params, "t");
    ASSERT_EQ(g.res[0], 8u);
    ASSERT_EQ(g.cell[0], 0.25f);
    expect_brute(cube, c, test::lattice_rays(1.0f, Vec3(0.0f)), "cube lattice", 500);
    // Other resolutions put the planes between the vertices.
    for (float density : {0.1f, 3.0f, 30.0f}) {
        c.density = density;
        expect_brute(cube, c, test::lattice_rays(1.0f, Vec3(0.0f)), "cube lattice, density " + std::to_string(density), 500);
    }
}

TEST(GridHardCases, HugeAndTinyCoordinates) {
    const std::vector<Vec3> unit = test::tessellated_cube(4);
    // The shared triangle test squares coordinates, so scenes stay within about 1e+-15 (beyond
    // that brute force finds nothing to compare with either).
    for (const auto& [scale, offset] : {std::pair<float, float>{1e15f, 0.0f}, {1e-15f, 0.0f}, {1.0f, 1e6f},
                                        {1e-3f, 1e4f}, {3e12f, -7e13f}}) {
        std::vector<Vec3> soup;
        for (const Vec3& v : unit) soup.push_back(Vec3(offset) + scale * v);
        const Scene scene = test::make_scene(soup);
        const std::string what = "cube x " + std::to_string(scale) + " + " + std::to_string(offset);
        expect_brute(scene, GridConfig{}, test::lattice_rays(scale, Vec3(offset)), what, 100);
        // Random rays through the scaled soup.
        const Scene soup_scene = [&, scale = scale, offset = offset] {  // C++17: no captured bindings
            const Scene s = test::random_soup(11, 500);
            std::vector<Vec3> scaled;
            for (const Triangle& t : s.triangles)
                for (const Vec3& v : {t.v0, t.v1, t.v2}) scaled.push_back(Vec3(offset) + scale * v);
            return test::make_scene(scaled);
        }();
        expect_brute(soup_scene, GridConfig{}, test::random_rays(soup_scene, test::hw_triangles(soup_scene), 3, 3000),
                     "soup " + what, 100);
    }
}

TEST(GridHardCases, DegenerateTrianglesEmptyCellsAndEmptyScenes) {
    // Two far clusters (mostly empty cells between), with zero-area triangles mixed in.
    std::vector<Vec3> soup;
    Rng rng(5);
    for (int i = 0; i < 400; ++i) {
        const Vec3 c = (i % 2 ? Vec3(100.0f) : Vec3(0.0f)) + test::random_point(rng, Vec3(0.0f), Vec3(2.0f));
        Vec3 p[3] = {c, c + test::random_point(rng, Vec3(-0.3f), Vec3(0.3f)), c + test::random_point(rng, Vec3(-0.3f), Vec3(0.3f))};
        if (i % 7 == 0) p[2] = p[1];                    // repeated vertex
        if (i % 11 == 0) p[2] = 2.0f * p[1] - p[0];    // collinear
        if (i % 13 == 0) p[1] = p[2] = p[0];            // a point
        soup.insert(soup.end(), {p[0], p[1], p[2]});
    }
    const Scene scene = test::make_scene(soup);
    expect_brute(scene, GridConfig{}, test::random_rays(scene, test::hw_triangles(scene), 9, 4000), "clusters", 300);
    // An empty scene: one empty cell; every ray misses after the bounds test (and one cell).
    const std::unique_ptr<Accel> empty = load_accel(grid_image(Scene{}), "empty");
    for (const Ray& r : test::lattice_rays(1.0f, Vec3(0.0f))) {
        WorkCounts w;
        EXPECT_FALSE(empty->trace(r, TraversalMode::closest_hit, &w).valid());
        EXPECT_LE(w.cell_steps, 1u);
        EXPECT_EQ(w.tri_tests, 0u);
    }
}

TEST(GridValidation, CorruptImagesAreRefusedByName) {
    const AccelImage good = grid_image(test::random_soup(4, 300));
    EXPECT_NO_THROW(load_accel(AccelImage(good), "good"));
    auto refused = [&](const std::function<void(AccelImage&)>& edit) {
        AccelImage bad = good;
        edit(bad);
        return error_of([&] { load_accel(std::move(bad), "bad.rtt"); });
    };
    std::string msg = refused([](AccelImage& im) { im.region("cells").records<GridCell>()[3].first_ref = 1u << 30; });
    EXPECT_NE(msg.find("bad.rtt: grid: cell 3 lists prim_refs 1073741824"), std::string::npos) << msg;
    msg = refused([](AccelImage& im) { im.region("cells").records<GridCell>()[0].ref_count = 0xFFFFFFFFu; });
    EXPECT_NE(msg.find("cell 0 lists prim_refs"), std::string::npos) << msg;
    msg = refused([](AccelImage& im) { im.params["resolution"][0] = im.params["resolution"][0].get<uint32_t>() + 1; });
    EXPECT_NE(msg.find("cells, region 'cells' holds"), std::string::npos) << msg;
    const uint32_t tris = uint32_t(good.region("triangles").count);
    msg = refused([&](AccelImage& im) { im.region("prim_refs").records<uint32_t>()[7] = tris; });
    EXPECT_NE(msg.find("prim_refs entry 7 names triangle " + std::to_string(tris) + " of " + std::to_string(tris)),
              std::string::npos) << msg;
    msg = refused([](AccelImage& im) { im.params["cell_size"][1] = 0.0; });
    EXPECT_NE(msg.find("'cell_size' must be finite and > 0"), std::string::npos) << msg;
    msg = refused([](AccelImage& im) { im.params.erase("origin"); });
    EXPECT_NE(msg.find("bad.rtt: grid params: 'origin' is missing"), std::string::npos) << msg;
    msg = refused([](AccelImage& im) { im.params["origin"][2] = 1e30; });
    EXPECT_NE(msg.find("coincide"), std::string::npos) << msg;
    msg = refused([](AccelImage& im) { im.region("prim_refs").kind = DataKind::node; });
    EXPECT_NE(msg.find("data kinds cell, prim_ref and triangle"), std::string::npos) << msg;
    msg = refused([](AccelImage& im) { im.regions.erase(im.regions.begin()); });
    EXPECT_NE(msg.find("no region 'cells'"), std::string::npos) << msg;
}

TEST(GridRegistry, BuildsThroughTheRegistryAndRoundTripsThroughATrace) {
    const Scene scene = test::random_soup(6, 800);
    AccelOptions o;
    o.kind = "grid";
    const AccelImage built = build_accel(scene, o);  // empty builder: the grid's default
    EXPECT_EQ(built.stats.at("builder"), "uniform");
    EXPECT_GT(built.stats.at("footprint_bytes").get<uint64_t>(), 0u);
    o.builder = "binned";
    EXPECT_NE(error_of([&] { build_accel(scene, o); }).find("has no builder 'binned' (it takes: uniform)"),
              std::string::npos);
    const std::string path = (test::process_temp_dir("grid") / "grid.rtt").string();
    {
        TraceWriter w(path);
        write_accel_image(w, built);
        w.close();
    }
    TraceReader r(path);
    const std::unique_ptr<Accel> read = load_accel(read_accel_image(r), path);
    std::filesystem::remove(path);
    EXPECT_EQ(read->kind(), "grid");
    EXPECT_EQ(read->image().descriptor(), built.descriptor());
    // Deterministic: the same scene gives the same bytes.
    const AccelImage again = grid_image(scene);
    for (size_t i = 0; i < again.regions.size(); ++i)
        EXPECT_EQ(std::memcmp(again.regions[i].bytes.data(), built.regions[i].bytes.data(), again.regions[i].bytes.size()), 0);
    const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), 8, 1000);
    const std::unique_ptr<Accel> direct = load_accel(AccelImage(built), "direct");
    EXPECT_EQ(test::compare_rays(test::tracer(*read), test::tracer(*direct), rays, "read back").diffs, 0);
}

TEST(GridLocality, BricksCoverEveryCellOnceWithinTheBudget) {
    const Scene scene = test::random_soup(7, 3000);
    const std::unique_ptr<Accel> g = load_accel(grid_image(scene), "t");
    const GridView& v = static_cast<const GridAccel&>(*g).view();
    size_t previous = 0;
    for (uint64_t budget : {1ull << 20, 16ull << 10, 2ull << 10, 64ull}) {
        const LocalityPartition p = g->partition(budget);
        ASSERT_EQ(p.group_of.size(), v.cell_count);
        std::vector<uint32_t> cells(p.treelets.size(), 0);
        for (uint32_t group : p.group_of) {
            ASSERT_LT(group, p.treelets.size());
            ++cells[group];
        }
        uint64_t bytes = 0;
        for (size_t t = 0; t < p.treelets.size(); ++t) {
            EXPECT_EQ(cells[t], p.treelets[t].nodes);
            EXPECT_TRUE(p.treelets[t].bytes <= budget || p.treelets[t].nodes == 1) << "brick " << t;
            EXPECT_EQ(p.group_of[p.treelets[t].root], t);
            bytes += p.treelets[t].bytes;
        }
        EXPECT_EQ(bytes, v.cell_count * sizeof(GridCell) + v.ref_count * (kRefBytes + sizeof(HwTriangle)));
        EXPECT_GE(p.treelets.size(), previous);  // a smaller budget never makes fewer bricks
        previous = p.treelets.size();
    }
    EXPECT_GT(previous, 1u);
    EXPECT_EQ(previous, v.cell_count);  // 64 bytes hold no two cells with references
}

}  // namespace
}  // namespace rtsim
