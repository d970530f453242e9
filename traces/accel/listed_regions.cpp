// Opening a listing structure's regions (listed_regions.h).
#include "traces/accel/listed_regions.h"

#include "traces/common/error.h"

namespace rtsim {

void check_listed_regions(const AccelImage& image, const std::string& structure, const std::string& cells_name,
                          DataKind cells_kind, uint32_t cell_bytes, const std::string& source) {
    const Region& cells = image.region(cells_name);
    const Region& refs = image.region("prim_refs");
    const Region& tris = triangle_region(image);
    require(cells.record_bytes == cell_bytes && refs.record_bytes == kRefBytes && triangle_records_ok(tris),
            source + ": " + structure + " regions must hold " + std::to_string(cell_bytes) + "-byte " + cells_name +
                ", 4-byte references and 48-byte triangles");
    require(cells.kind == cells_kind && refs.kind == DataKind::prim_ref && tris.kind == DataKind::triangle,
            source + ": " + structure + " regions must be of data kinds " + data_kind_name(cells_kind) +
                ", prim_ref and triangle");
}

ListedRegions open_listed_regions(const AccelImage& image, TriangleStore& triangles, const std::string& structure,
                                  const std::string& cells_name, DataKind cells_kind, uint32_t cell_bytes,
                                  const std::string& source) {
    check_listed_regions(image, structure, cells_name, cells_kind, cell_bytes, source);
    const Region& refs = image.region("prim_refs");
    triangles = TriangleStore::open(image, source);
    ListedRegions r;
    r.cells = &image.region(cells_name);
    r.list = RefListView{refs.records<uint32_t>(), triangles.triangles(), refs.base, triangles.addressing()};
    r.ref_count = refs.count;
    r.triangle_count = triangles.count();
    return r;
}

}  // namespace rtsim
