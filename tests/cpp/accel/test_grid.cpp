// The uniform grid: layout invariants, the density heuristic, the conservative DDA (exactly the
// cells the robust box test accepts, in entry order), hits identical to the binary BVH and brute
// force (random soups, every procedural scene, the numerical hard cases), work counts equal to
// what the plans asked for, validation refusing corrupt images by name, and bricks.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <set>

#include "tests/cpp/error_of.h"
#include "structure_test_util.h"
#include "traces/accel/accel_io.h"
#include "traces/accel/bvh2/bvh2.h"
#include "traces/accel/grid/grid.h"
#include "traces/common/error.h"
#include "traces/isect/ray_box_kernel.h"
#include "traces/isect/leaf_kernel.h"
#include "traces/raygen/auto_framing.h"
#include "traces/raygen/camera.h"

namespace rtsim {
namespace {

std::unique_ptr<Accel> grid_of(const Scene& scene, float density = 4.0f) {
    GridConfig c;
    c.density = density;
    return load_accel(grid_image(scene, c), "test grid");
}

const GridView& view_of(const Accel& a) { return static_cast<const GridAccel&>(a).view(); }

using test::error_of;

/// Hits of `grid` against brute force and the binary BVH on `rays`: zero differences.
void expect_same_hits(const Accel& grid, const Scene& scene, const std::vector<Ray>& rays, const std::string& what,
                      int min_hits = 1) {
    const std::vector<HwTriangle> tris = test::hw_triangles(scene);
    const test::Agreement brute = test::compare_rays(test::tracer(grid), test::brute_force(tris), rays, what + " vs brute");
    EXPECT_EQ(brute.diffs, 0) << what;
    EXPECT_GE(brute.hits, min_hits) << what << ": the rays must exercise hits";
    if (!scene.triangles.empty()) {
        const std::unique_ptr<Accel> bvh = test::bvh2_of(scene);
        EXPECT_EQ(test::compare_rays(test::tracer(grid), test::tracer(*bvh), rays, what + " vs bvh2").diffs, 0) << what;
    }
}

TEST(GridLayout, InvariantsAndDensityHeuristic) {
    for (uint64_t seed : {1, 2}) {
        const Scene scene = test::random_soup(seed, 2000);
        for (float density : {0.5f, 4.0f, 16.0f}) {
            const std::unique_ptr<Accel> g = grid_of(scene, density);
            const GridView& v = view_of(*g);
            EXPECT_NO_THROW(check_grid_invariants(v, scene));
            // About lambda x N cells (rounding each axis moves it by a factor well under 2).
            const double want = double(density) * 2000.0, got = double(v.cell_count);
            EXPECT_GT(got, want / 2.0) << density;
            EXPECT_LT(got, want * 2.0) << density;
            // Every triangle in at least one cell, and cubic cells in a cubic scene.
            EXPECT_GE(v.ref_count, v.triangle_count);
            const GridGeometry& geo = v.geometry;
            EXPECT_LT(std::max({geo.cell[0], geo.cell[1], geo.cell[2]}) / std::min({geo.cell[0], geo.cell[1], geo.cell[2]}),
                      1.5f);
            EXPECT_TRUE(geo.bounds().contains(scene.bounds));
        }
    }
    // A flat scene (all in z = 0) gets one slab in z; an empty one one empty cell.
    std::vector<Vec3> flat;
    for (int i = 0; i < 10; ++i) flat.insert(flat.end(), {Vec3(float(i), 0, 0), Vec3(float(i) + 1, 0, 0), Vec3(float(i), 1, 0)});
    const Scene flat_scene = test::make_scene(flat);
    const std::unique_ptr<Accel> g = grid_of(flat_scene);
    EXPECT_EQ(view_of(*g).geometry.res[2], 1u);
    EXPECT_GT(view_of(*g).geometry.res[0], 1u);
    EXPECT_NO_THROW(check_grid_invariants(view_of(*g), flat_scene));
    const std::unique_ptr<Accel> empty = load_accel(grid_image(Scene{}), "empty");
    EXPECT_EQ(view_of(*empty).cell_count, 1u);
    EXPECT_EQ(view_of(*empty).ref_count, 0u);
}

TEST(GridLayout, CheckerCatchesAMissingReference) {
    const Scene scene = test::random_soup(3, 300);
    AccelImage image = grid_image(scene);
    // Drop the last entry of the first non-empty cell's list.
    const std::unique_ptr<Accel> good = load_accel(AccelImage(image), "good");
    GridCell* cells = image.region("cells").records<GridCell>();
    uint64_t c = 0;
    while (cells[c].ref_count == 0) ++c;
    cells[c].ref_count -= 1;
    // Validation refuses it (lists back to back, each reference in one: bounded work per ray)...
    std::string msg = error_of([&] { load_accel(AccelImage(image), "bad"); });
    EXPECT_NE(msg.find("bad: grid: cell " + std::to_string(c + 1) + "'s list starts at prim_refs"), std::string::npos)
        << msg;
    // ... and so does the builder's checker, on a view that skips validation.
    GridView view = view_of(*good);
    view.cells = cells;
    msg = error_of([&] { check_grid_invariants(view, scene); });
    EXPECT_NE(msg.find("does not follow"), std::string::npos) << msg;
}

TEST(GridDda, VisitsExactlyTheCellsTheBoxTestAccepts) {
    GridGeometry g;
    const uint32_t res[3] = {5, 4, 3};
    for (int a = 0; a < 3; ++a) g.res[a] = res[a], g.origin[a] = -1.0f + 0.25f * float(a), g.cell[a] = 0.5f;
    Rng rng(17);
    int rays = 0, visits = 0;
    for (int i = 0; i < 20000; ++i) {
        // Origins on planes, plane intersections, corners and anywhere; axis and diagonal
        // directions (simultaneous crossings); +-0 components.
        Vec3 o = test::random_point(rng, Vec3(-2.0f), Vec3(2.5f));
        for (int a = 0; a < 3; ++a)
            if (rng.next() < 0.4f) o[a] = g.plane(a, uint32_t(rng.next() * float(g.res[a] + 1)) % (g.res[a] + 1));
        Vec3 d = rng.next() < 0.3f ? Vec3(rng.next() < 0.5f ? 1.0f : -1.0f, rng.next() < 0.5f ? 1.0f : -1.0f,
                                          rng.next() < 0.5f ? 1.0f : -1.0f)
                                   : test::random_direction(rng);
        for (int a = 0; a < 3; ++a)
            if (rng.next() < 0.2f) d[a] = rng.next() < 0.5f ? 0.0f : -0.0f;
        if (d == Vec3(0.0f)) d.x = 1.0f;
        const float tmin = rng.next() < 0.3f ? rng.next() * 2.0f : 0.0f;
        const float tmax = rng.next() < 0.3f ? tmin + rng.next() * 3.0f : std::numeric_limits<float>::infinity();
        const Ray ray = test::make_ray(o, d, tmin, tmax);
        const RayBoxPre pre = ray_box_precompute(ray);
        const float cull = detail::cull_distance(tmax);
        std::set<uint32_t> want;
        for (uint32_t z = 0; z < g.res[2]; ++z)
            for (uint32_t y = 0; y < g.res[1]; ++y)
                for (uint32_t x = 0; x < g.res[0]; ++x) {
                    const uint32_t xyz[3] = {x, y, z};
                    float lo[3], hi[3], tn;
                    for (int a = 0; a < 3; ++a) lo[a] = g.plane(a, xyz[a]), hi[a] = g.plane(a, xyz[a] + 1);
                    // A cell entered only at t = +inf can hold no hit: not visited.
                    if (detail::box_kernel(pre, lo, hi, tmin, cull, &tn) && tn < std::numeric_limits<float>::infinity())
                        want.insert(g.cell_index(x, y, z));
                }
        const Aabb b = g.bounds();
        const float blo[3] = {b.lo.x, b.lo.y, b.lo.z}, bhi[3] = {b.hi.x, b.hi.y, b.hi.z};
        float t0;
        std::vector<uint32_t> got;
        float last_entry = -std::numeric_limits<float>::infinity();
        bool ordered = true;
        if (detail::box_kernel(pre, blo, bhi, tmin, cull, &t0)) {
            GridDda dda;
            dda.begin(g, pre, t0);
            uint32_t cell;
            while (dda.next(cull, &cell)) {
                got.push_back(cell);
                ordered = ordered && dda.entry() >= last_entry;
                last_entry = dda.entry();
            }
        }
        ++rays;
        visits += int(got.size());
        std::set<uint32_t> got_set(got.begin(), got.end());
        ASSERT_EQ(got_set.size(), got.size()) << "ray " << i << ": a cell visited twice";
        ASSERT_EQ(got_set, want) << "ray " << i << " o=(" << o.x << "," << o.y << "," << o.z << ") d=(" << d.x << ","
                                 << d.y << "," << d.z << ") tmin " << tmin << " tmax " << tmax;
        ASSERT_TRUE(ordered) << "ray " << i << ": cells out of entry order";
    }
    EXPECT_GT(visits, rays);  // the rays do cross cells
}

TEST(GridTrace, HitsEqualBvh2AndBruteForceOnRandomSoups) {
    for (uint64_t seed = 1; seed <= 4; ++seed) {
        const Scene scene = test::random_soup(seed, 200 + 400 * int(seed));
        const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), seed * 91, 4000);
        for (float density : {0.05f, 1.0f, 8.0f}) {
            const std::unique_ptr<Accel> g = grid_of(scene, density);
            expect_same_hits(*g, scene, rays, "soup " + std::to_string(seed) + " density " + std::to_string(density),
                             400);
        }
    }
}

TEST(GridTrace, HitsEqualBvh2OnProceduralScenes) {
    for (const std::string& name : procedural_scene_names()) {
        const Scene& scene = test::procedural(name);
        const std::unique_ptr<Accel> g = grid_of(scene), bvh = test::bvh2_of(scene);
        const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), 7, 6000);
        const test::Agreement ag = test::compare_rays(test::tracer(*g), test::tracer(*bvh), rays, name);
        EXPECT_EQ(ag.diffs, 0) << name;
        EXPECT_GT(ag.hits, 600) << name;
        EXPECT_NO_THROW(check_grid_invariants(view_of(*g), scene)) << name;
    }
}

TEST(GridTrace, WorkIsWhatThePlansAskedForAndTraceEqualsTheStepper) {
    const Scene scene = test::random_soup(5, 1500);
    const std::unique_ptr<Accel> g = grid_of(scene);
    const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), 55, 3000);
    int max_fetches = 0;
    uint64_t cells = 0, refs = 0;
    for (const Ray& r : rays)
        for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
            std::unique_ptr<Stepper> s = g->make_stepper();
            const WorkCounts planned = test::tally_plans(*s, r, mode, &max_fetches);
            const Hit stepped = s->hit();
            WorkCounts traced;
            const Hit fused = g->trace(r, mode, &traced);
            ASSERT_EQ(planned, s->work());
            ASSERT_EQ(traced, s->work());
            ASSERT_TRUE(test::same_hit(fused, stepped, TraversalMode::closest_hit));
            ASSERT_EQ(s->stack_size(), 0);
            ASSERT_EQ(s->work().steps, s->work().cell_steps);  // every step that fetched fetched a cell
            ASSERT_LE(s->work().box_tests, 1u);
            cells += s->work().cell_steps, refs += s->work().refs;
        }
    EXPECT_LE(max_fetches, StepPlan::kMaxFetches);
    EXPECT_EQ(max_fetches, StepPlan::kMaxFetches);  // some cells hold more than one batch
    EXPECT_GT(cells, 0u);
    EXPECT_GT(refs, 0u);
    EXPECT_EQ(g->max_stack_entries(), 0u);
    const std::vector<OpKind> ops = g->op_kinds();
    EXPECT_NE(std::find(ops.begin(), ops.end(), OpKind::cell), ops.end());
}

}  // namespace
}  // namespace rtsim

// The density heuristic on Sponza (disabled: needs the shared scenes and a few minutes); run with
//   test_accel --gtest_also_run_disabled_tests --gtest_filter='*DensityOnSponza'
// Prints, per lambda, the grid's size and the mean work of 160x120 primary rays (docs/accel.md).
namespace rtsim {
namespace {

TEST(GridBenchmark, DISABLED_DensityOnSponza) {
    const std::string path = std::string(RTSIM_SCENES_DIR) + "/sponza/Sponza.gltf";
    if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not found";
    const Scene scene = load_gltf(path);
    const std::unique_ptr<Accel> bvh = test::bvh2_of(scene);
    std::string why;
    const Camera cam = scene.cameras.empty() ? auto_frame(scene, *bvh, 4.0f / 3.0f, &why) : scene.cameras[0];
    const PinholeCamera pinhole = make_camera(cam, 160, 120);
    std::vector<Ray> rays;
    for (uint32_t y = 0; y < 120; ++y)
        for (uint32_t x = 0; x < 160; ++x) rays.push_back(primary_ray(pinhole, x, y, 160, 120));
    for (float density : {0.5f, 1.0f, 2.0f, 4.0f, 8.0f, 16.0f}) {
        const auto t0 = std::chrono::steady_clock::now();
        const std::unique_ptr<Accel> g = grid_of(scene, density);
        const double build = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        double cells = 0, refs = 0, tris = 0;
        int diffs = 0;
        for (const Ray& r : rays) {
            WorkCounts w;
            const Hit h = g->trace(r, TraversalMode::closest_hit, &w);
            diffs += !test::same_hit(h, bvh->trace(r, TraversalMode::closest_hit), TraversalMode::closest_hit);
            cells += w.cell_steps, refs += w.refs, tris += w.tri_tests;
        }
        const double n = double(rays.size());
        const GridView& v = view_of(*g);
        std::printf("lambda %5.1f: %4u x %4u x %4u = %8llu cells, %9llu refs, %6.1f MiB, build %6.0f ms | per ray: "
                    "%6.1f cell steps, %7.1f refs, %7.1f tri tests, %d diffs\n",
                    density, v.geometry.res[0], v.geometry.res[1], v.geometry.res[2],
                    (unsigned long long)v.cell_count, (unsigned long long)v.ref_count,
                    double(g->image().footprint_bytes()) / 1048576.0, build, cells / n, refs / n, tris / n, diffs);
        EXPECT_EQ(diffs, 0);
    }
}

}  // namespace
}  // namespace rtsim
