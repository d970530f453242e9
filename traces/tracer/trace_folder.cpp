#include "traces/tracer/trace_folder.h"

#include <filesystem>
#include <fstream>

#include "traces/accel/accel_io.h"
#include "traces/common/build_info.h"
#include "traces/common/error.h"
#include "traces/common/files.h"
#include "traces/common/stopwatch.h"
#include "traces/shading/texels.h"

namespace rtsim {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string created(const std::string& out_dir) {
    require_utf8_path(out_dir, "output folder");
    make_output_folder(out_dir, "trace output");
    return out_dir;
}

}  // namespace

TraceFolderWriter::TraceFolderWriter(const std::string& out_dir, const AccelImage& image)
    : m_out_dir(created(out_dir)),
      m_writer((fs::path(out_dir) / "trace.rtt").string()),
      m_start(std::chrono::steady_clock::now()) {
    write_accel_image(m_writer, image);
}

void TraceFolderWriter::set_shading(const Scene& scene, ShadingScene shading) {
    m_scene = &scene;
    m_shading = std::move(shading);
    m_tri.resize(scene.triangle_count());
    for (size_t p = 0; p < m_tri.size(); ++p) m_tri[p] = tri_shade_record(scene, uint32_t(p));
    m_writer.append(SectionKind::materials, m_shading.materials);
    if (m_shading.has_textures()) m_writer.append(SectionKind::textures, m_shading.textures);
    m_writer.append(SectionKind::tri_shading, m_tri);
}

void TraceFolderWriter::add_wavefront(const WorkloadPlan& plan, const std::vector<PendingRay>& rays,
                                      const WavefrontResult& res) {
    std::vector<RayRecord> ray_rec;
    std::vector<HitRecord> hit_rec;
    std::vector<WorkRecord> work_rec;
    std::vector<ShadeRecord> shade_rec;
    std::vector<uint64_t> fetches;
    std::vector<int64_t> index(rays.size(), -1);
    m_counts.add_rejected(res.rejected);
    for (size_t i = 0; i < rays.size(); ++i) {
        const PendingRay& r = rays[i];
        const bool written = plan.wants(r.kind);
        m_counts.add(r.kind, r.depth, res.hits[i], res.work[i], written);
        if (!written) continue;
        index[i] = int64_t(m_rays_written + ray_rec.size());
        ray_rec.push_back(to_record(r.ray, r.kind, r.pixel, r.depth, r.any_hit));
        hit_rec.push_back(to_record(res.hits[i]));
        work_rec.push_back(WorkRecord::of(res.work[i]));
        if (m_scene) shade_rec.push_back(shade_record(r, res.hits[i], &fetches));
    }
    m_wave_index = std::move(index);
    m_rays_written += ray_rec.size();
    m_fetches += fetches.size();
    m_writer.append(SectionKind::rays, ray_rec);
    m_writer.append(SectionKind::hits, hit_rec);
    m_writer.append(SectionKind::work, work_rec);
    if (m_scene) {
        m_writer.append(SectionKind::shading, shade_rec);
        m_writer.append(SectionKind::texel_fetches, fetches);
    }
}

ShadeRecord TraceFolderWriter::shade_record(const PendingRay& r, const Hit& hit, std::vector<uint64_t>* fetches) {
    ShadeRecord s{};
    s.parent = r.parent >= 0 && size_t(r.parent) < m_wave_index.size() ? m_wave_index[size_t(r.parent)] : -1;
    s.material = kNoMaterial;
    s.shader = kMissShader;
    s.first_fetch = m_fetches + fetches->size();
    s.cone_width = r.cone_width;
    s.cone_spread = r.cone_spread;
    if (shades_hit(r.any_hit, hit) && size_t(hit.prim) < m_tri.size()) {
        const TriShadeRecord& tri = m_tri[size_t(hit.prim)];
        s.material = tri.material;
        if (tri.material < m_shading.materials.size()) s.shader = m_shading.materials[tri.material].shader;
        s.samples = uint16_t(hit_texels(m_shading.materials, m_shading.textures, tri, hit, r.ray.direction,
                                        RayCone{r.cone_width, r.cone_spread}, fetches));
    }
    return s;
}

void TraceFolderWriter::add_frame(uint64_t first_ray) {
    const FrameRecord frame{first_ray, m_rays_written - first_ray};
    m_writer.append(SectionKind::frames, &frame, 1, sizeof(FrameRecord));
}

json TraceFolderWriter::finish(const Scene& scene, const SceneLabel& label, const AccelImage& image,
                               double load_ms, std::chrono::steady_clock::time_point started, json extra) {
    m_writer.close();
    const double trace_ms = ms_since(m_start);
    json files = {{"trace", "trace.rtt"}};
    if (extra.contains("files")) {
        files.update(extra["files"]);
        extra.erase("files");
    }
    json manifest = {
        {"format", "rtsim-trace"},
        {"trace_version", kTraceVersion},
        {"rtsim_version", rtsim_version()},
        {"git", rtsim_git_hash()},
        {"scene", scene_json(scene, label.name, label.procedural)},
        {"accel", accel_json(image)},
        {"counts", m_counts.to_json()},
        {"files", files},
        {"shading", m_scene ? m_shading.to_json(*m_scene) : json(nullptr)},
        {"timing_ms",
         {{"load", load_ms}, {"accel", image.build_ms}, {"trace", trace_ms}, {"total", ms_since(started)}}},
    };
    manifest.update(extra);
    const std::string path = (fs::path(m_out_dir) / "manifest.json").string();
    std::ofstream out(path);
    out << manifest.dump(2) << "\n";
    require(bool(out), path + ": cannot write the manifest");
    return manifest;
}

}  // namespace rtsim
