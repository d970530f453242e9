// The uniform grid's builder (grid.h): resolution from the density heuristic, then every
// triangle listed in every cell its box overlaps (two passes: count, then fill).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "traces/accel/grid/grid.h"
#include "traces/bvh/build_tree.h"
#include "traces/common/build_budget.h"
#include "traces/common/error.h"
#include "traces/scene/scene.h"

namespace rtsim {
namespace {

void validate(const GridConfig& c) {
    require(std::isfinite(c.density) && c.density > 0.0f && c.density <= 1e6f,
            "GridConfig.density must be in (0, 1e6], got " + std::to_string(c.density));
    require(c.max_resolution >= 1 && c.max_resolution <= (1u << 16), "GridConfig.max_resolution must be in 1..65536");
    require(c.max_cells >= 1 && c.max_cells <= (1ull << 32), "GridConfig.max_cells must be in 1..2^32");
}

/// Cells per axis: extent x cbrt(lambda N / V) (Cleary & Wyvill 1988, "Analysis of an algorithm
/// for fast ray tracing using uniform space subdivision"; Wald et al. 2006, "Ray tracing animated
/// scenes using coherent grid traversal", M = lambda N). Flat scenes use the area (or length)
/// of their non-zero extents; an axis of zero extent gets one cell.
void choose_resolution(const Vec3& extent, uint64_t n, const GridConfig& c, uint32_t res[3]) {
    double cells = std::min(double(c.density) * double(n), double(c.max_cells));
    for (;;) {
        double measure = 1.0;
        int dims = 0;
        for (int a = 0; a < 3; ++a)
            if (extent[a] > 0.0f) measure *= double(extent[a]), ++dims;
        const double per_length = dims ? std::pow(cells / measure, 1.0 / dims) : 0.0;
        uint64_t total = 1;
        for (int a = 0; a < 3; ++a) {
            const double r = extent[a] > 0.0f ? std::round(double(extent[a]) * per_length) : 1.0;
            res[a] = uint32_t(std::min(std::max(r, 1.0), double(c.max_resolution)));
            total *= res[a];
        }
        if (total <= c.max_cells) return;
        cells *= 0.9 * double(c.max_cells) / double(total);  // rounding overshot: shrink and retry
    }
}

/// The geometry over `bounds`: cell = extent / res rounded up until plane res covers hi, and the
/// resolution lowered on an axis whose planes would coincide at this magnitude.
GridGeometry make_geometry(const Aabb& bounds, uint64_t n, const GridConfig& c) {
    GridGeometry g;
    const Vec3 extent = bounds.hi - bounds.lo;
    choose_resolution(extent, n, c, g.res);
    const float largest = std::max(extent.x, std::max(extent.y, extent.z));
    for (int a = 0; a < 3; ++a) {
        g.origin[a] = bounds.lo[a];
        for (;;) {
            // A flat axis gets one slab of a size taken from the other axes (or 1).
            g.cell[a] = extent[a] > 0.0f ? extent[a] / float(g.res[a]) : (largest > 0.0f ? largest : 1.0f);
            while (!(g.plane(a, 1) > g.origin[a]))  // too small to move the origin: double it
                g.cell[a] = g.cell[a] > 0.0f ? 2.0f * g.cell[a] : std::numeric_limits<float>::denorm_min();
            while (g.plane(a, g.res[a]) < bounds.hi[a])  // rounding fell short of hi: round up
                g.cell[a] = std::nextafter(g.cell[a], std::numeric_limits<float>::infinity());
            bool increasing = true;
            for (uint32_t k = 0; k < g.res[a] && increasing; ++k) increasing = g.plane(a, k) < g.plane(a, k + 1);
            if (increasing) break;
            g.res[a] = std::max(1u, g.res[a] / 2);  // planes would coincide at this magnitude
        }
        require(std::isfinite(g.plane(a, g.res[a])), "grid: the scene's bounds are too large for a grid");
    }
    return g;
}

/// The grid's settings as a message names them.
std::string settings_text(const GridConfig& c) {
    char text[160];
    std::snprintf(text, sizeof text, "density=%g, max_resolution=%u, max_cells=%llu", double(c.density),
                  c.max_resolution, static_cast<unsigned long long>(c.max_cells));
    return text;
}

/// Refuses a grid whose references overflow the 32-bit lists or whose cells and lists would not
/// fit the memory a build may take, with the figures and the settings that made them.
void check_grid_budget(const GridGeometry& g, const GridConfig& c, double references, size_t n) {
    char what[200];
    std::snprintf(what, sizeof what, "grid (%s): %u x %u x %u = %llu cells", settings_text(c).c_str(), g.res[0],
                  g.res[1], g.res[2], static_cast<unsigned long long>(g.cell_count()));
    const std::string advice = "lower density or max_cells (--build-set density=4)";
    require(references < double(1ull << 32), std::string(what) + " listing " + std::to_string(uint64_t(references)) +
                                                 " references, more than the 2^32 a list index holds; " + advice);
    // The build holds the cells' counts (8 B), the cell records (8 B), the lists (4 B per
    // reference), each triangle's box, range and record, then the image copies nothing more.
    const double cells = double(g.cell_count());
    const double bytes = cells * 16.0 + references * 4.0 + double(n) * (24.0 + 24.0 + sizeof(HwTriangle));
    char detail[200];
    std::snprintf(detail, sizeof detail, "%s of cells and counts, %.0f references = %s", format_bytes(cells * 16.0).c_str(),
                  references, format_bytes(references * 4.0).c_str());
    check_build_memory(bytes, what, detail, advice);
}

/// What the manifest records about a grid build.
nlohmann::json build_stats(const GridGeometry& g, const GridConfig& config, const GridCell* cells, uint64_t total,
                           size_t n) {
    uint32_t max_list = 0;
    uint64_t empty = 0;
    for (uint64_t c = 0; c < g.cell_count(); ++c) {
        max_list = std::max(max_list, cells[c].ref_count);
        empty += cells[c].ref_count == 0;
    }
    return {{"builder", "uniform"},
            {"config",
             {{"density", config.density}, {"max_resolution", config.max_resolution}, {"max_cells", config.max_cells}}},
            {"resolution", {g.res[0], g.res[1], g.res[2]}},
            {"cells", g.cell_count()},
            {"references", total},
            {"references_per_triangle", n ? double(total) / double(n) : 0.0},
            {"references_per_cell", double(total) / double(g.cell_count())},
            {"max_references_per_cell", max_list},
            {"empty_cell_fraction", double(empty) / double(g.cell_count())},
            {"cell_bytes", sizeof(GridCell)},
            {"node_bytes", sizeof(GridCell)},  // a cell is the record a step fetches
            {"triangle_bytes", sizeof(HwTriangle)}};
}

}  // namespace

AccelImage grid_image(const Scene& scene, const GridConfig& config) {
    validate(config);
    const size_t n = scene.triangles.size();
    require(n < (size_t(1) << 31), "grid: too many triangles (>= 2^31)");
    std::vector<Aabb> boxes(n);
    Aabb bounds;
    for (size_t i = 0; i < n; ++i) {
        const Triangle& t = scene.triangles[i];
        for (const Vec3& v : {t.v0, t.v1, t.v2}) {
            require(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z),
                    "grid: triangle " + std::to_string(i) + " has a non-finite vertex");
            boxes[i].grow(v);
        }
        bounds.grow(boxes[i]);
    }
    if (n == 0) bounds = Aabb{Vec3(0.0f), Vec3(0.0f)};
    const GridGeometry g = make_geometry(bounds, n, config);

    // Each triangle's range of cells per axis; the references they make and the memory of the
    // cells and lists are known from the ranges before anything of the grid's size is allocated.
    std::vector<uint32_t> range(6 * n);
    double references = 0.0;
    for (size_t i = 0; i < n; ++i) {
        uint32_t* r = &range[6 * i];
        for (int a = 0; a < 3; ++a)
            require(g.slab_range(a, boxes[i].lo[a], boxes[i].hi[a], &r[2 * a], &r[2 * a + 1]),
                    "grid: triangle " + std::to_string(i) + " is outside the grid (internal error)");
        references += double(r[1] - r[0] + 1) * double(r[3] - r[2] + 1) * double(r[5] - r[4] + 1);
    }
    check_grid_budget(g, config, references, n);
    // Then counts, offsets and lists (by triangle order).
    std::vector<uint64_t> count(g.cell_count() + 1, 0);
    for (size_t i = 0; i < n; ++i) {
        const uint32_t* r = &range[6 * i];
        for (uint32_t z = r[4]; z <= r[5]; ++z)
            for (uint32_t y = r[2]; y <= r[3]; ++y)
                for (uint32_t x = r[0]; x <= r[1]; ++x) ++count[g.cell_index(x, y, z) + 1];
    }
    for (size_t c = 1; c < count.size(); ++c) count[c] += count[c - 1];
    const uint64_t total = count.back();

    AccelImage image;
    image.kind = "grid";
    image.bounds = bounds;
    image.params = g.to_json();
    GridCell* cells = image.add_region<GridCell>("cells", DataKind::cell, g.cell_count()).records<GridCell>();
    uint32_t* refs = image.add_region<uint32_t>("prim_refs", DataKind::prim_ref, total).records<uint32_t>();
    HwTriangle* tris = image.add_region<HwTriangle>("triangles", DataKind::triangle, n).records<HwTriangle>();
    for (uint64_t c = 0; c < g.cell_count(); ++c) cells[c] = GridCell{uint32_t(count[c]), uint32_t(count[c + 1] - count[c])};
    for (size_t i = 0; i < n; ++i) {
        tris[i] = make_hw_triangle(scene, uint32_t(i));
        const uint32_t* r = &range[6 * i];
        for (uint32_t z = r[4]; z <= r[5]; ++z)
            for (uint32_t y = r[2]; y <= r[3]; ++y)
                for (uint32_t x = r[0]; x <= r[1]; ++x) refs[count[g.cell_index(x, y, z)]++] = uint32_t(i);
    }
    image.place_regions();
    image.stats = build_stats(g, config, cells, total, n);
    return image;
}

}  // namespace rtsim
