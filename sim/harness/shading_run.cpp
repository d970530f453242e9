// The frame in the harness (shading_run.h).
#include "sim/harness/shading_run.h"

#include <algorithm>

#include "traces/common/error.h"
#include "traces/shading/materials.h"

namespace rtsim {

namespace {

template <class T>
std::vector<T> read_section(TraceReader& reader, SectionKind kind) {
    return reader.has(kind) ? reader.read_all<T>(kind) : std::vector<T>{};
}

}  // namespace

std::unique_ptr<ShadingInputs> load_shading_inputs(TraceReader& reader, const SimConfig& config) {
    if (!config.shading.enabled || !reader.has(SectionKind::shading) || !reader.has(SectionKind::tri_shading) ||
        !reader.has(SectionKind::materials))
        return nullptr;
    auto in = std::make_unique<ShadingInputs>();
    in->materials = read_section<MaterialRecord>(reader, SectionKind::materials);
    in->textures = read_section<TextureRecord>(reader, SectionKind::textures);
    in->tris = read_section<TriShadeRecord>(reader, SectionKind::tri_shading);
    in->rays = read_section<RayRecord>(reader, SectionKind::rays);
    in->shade = read_section<ShadeRecord>(reader, SectionKind::shading);
    in->reference_fetches = read_section<uint64_t>(reader, SectionKind::texel_fetches);
    const std::string where = reader.path() + ": ";
    require(in->shade.size() == in->rays.size(), where + "SHAD has " + std::to_string(in->shade.size()) +
                                                     " records for " + std::to_string(in->rays.size()) + " rays");
    for (const MaterialRecord& m : in->materials) {
        in->shaders = std::max<uint32_t>(in->shaders, uint32_t(m.shader) + 1);
        for (int32_t t : m.texture)
            require(t < int32_t(in->textures.size()), where + "a material samples texture " + std::to_string(t) +
                                                          " of " + std::to_string(in->textures.size()));
    }
    // Textures lie above every region the model adds (traces/shading/materials.h).
    for (const TextureRecord& t : in->textures)
        require(t.base >= kTextureBase, where + "a texture at address " + std::to_string(t.base) +
                                            " lies below the textures' base (1 TiB), among the model's own regions");
    for (const TriShadeRecord& t : in->tris)
        require(t.material < in->materials.size(), where + "PTRI names material " + std::to_string(t.material) +
                                                        " of " + std::to_string(in->materials.size()));
    for (uint64_t i = 0; i < in->shade.size(); ++i) {
        const ShadeRecord& s = in->shade[i];
        require(s.parent < int64_t(i), where + "ray " + std::to_string(i) + "'s parent " + std::to_string(s.parent) +
                                           " does not come before it");
        require(s.first_fetch + uint64_t(s.samples) * kTexelsPerSample <= in->reference_fetches.size(),
                where + "ray " + std::to_string(i) + "'s texel addresses lie past TXFT's end");
    }
    // Wavefronts: the trace lists rays depth by depth (traces/tracer/tracer.cpp), frame after
    // frame in an animated trace; a wavefront never spans two frames.
    if (reader.has(SectionKind::frames)) in->frames = reader.read_all<FrameRecord>(SectionKind::frames);
    size_t frame = 0;
    for (uint64_t i = 0; i < in->rays.size(); ++i) {
        bool starts_frame = false;
        while (frame + 1 < in->frames.size() && i >= in->frames[frame + 1].first_ray) ++frame, starts_frame = true;
        if (i == 0 || starts_frame || in->rays[i].depth != in->rays[i - 1].depth) {
            in->wavefronts.push_back(0);
            in->wavefront_frame.push_back(uint32_t(frame));
        }
        ++in->wavefronts.back();
    }
    return in;
}

std::vector<FrameRecord> wavefront_segments(const ShadingInputs& inputs) {
    std::vector<FrameRecord> out;
    uint64_t first = 0;
    for (uint64_t n : inputs.wavefronts) {
        out.push_back({first, n});
        first += n;
    }
    if (out.empty()) out.push_back({0, 0});
    return out;
}

void wire_frame_loop(Top& top, const ShadingConfig& config, const ShadingInputs& inputs,
                     std::function<void(uint32_t, Cycle)> on_frame, FrameBuilds build) {
    ShadingBlock& shading = *top.shading();
    Dispatch& dispatch = top.dispatch();
    dispatch.hold_until(shading.raygen_end());
    if (config.frame_loop == FrameLoop::wavefront) {
        dispatch.set_barrier([&shading, &inputs, on_frame, build](uint32_t w, Cycle end) {
            Cycle released = shading.wavefront_end(w, end);
            const size_t n = inputs.wavefronts.size();
            const uint32_t frame = w < inputs.wavefront_frame.size() ? inputs.wavefront_frame[w] : 0;
            const bool last_of_frame = w + 1 >= n || (w + 1 < inputs.wavefront_frame.size() &&
                                                      inputs.wavefront_frame[w + 1] != frame);
            if (last_of_frame && on_frame) {
                // This frame, then any empty frames before the next one with rays (or the end).
                const uint32_t next = w + 1 < n ? inputs.wavefront_frame[w + 1] : uint32_t(inputs.frames.size());
                on_frame(frame, released);
                for (uint32_t e = frame + 1; e < next; ++e) on_frame(e, released);
            }
            // The next frame's camera rays, after this frame's last bounce is shaded, while the
            // build unit builds its structures (and those of the empty frames before it).
            if (last_of_frame && w + 1 < n) {
                const uint32_t next = inputs.wavefront_frame[w + 1];
                const Cycle built = build ? build(frame + 1, next, released) : released;
                released = shading.await_build(std::max(built, shading.begin_frame(next, released)));
            }
            return released;
        });
        return;
    }
    dispatch.set_gate([&shading](uint64_t id, Cycle* not_before) { return shading.parent_shaded(id, not_before); },
                      [&shading](uint64_t id) { return shading.parent_of(id); });
    // The ray finishing now is still counted in flight when the shading block sees it.
    shading.rt_idle = [&dispatch] { return dispatch.in_flight() <= 1; };
    shading.on_shaded = [&dispatch](const std::vector<uint64_t>& shaded) { dispatch.release(shaded); };
}

}  // namespace rtsim
