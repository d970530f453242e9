// glTF animation samplers (glTF 2.0 section 3.11): reading and checking them, and sampling
// LINEAR (slerp for rotations), STEP and CUBICSPLINE (Appendix C: Hermite spline with the
// keyframes' tangents scaled by the keyframe interval).
#include <algorithm>
#include <cmath>

#include "traces/scene/gltf_animation.h"

namespace rtsim::gltf {

namespace {

/// Floats per keyframe of a channel's path; weights: the morph targets of the node's mesh.
int path_width(const Source& src, Channel::Path path, int node, const std::string& where) {
    switch (path) {
        case Channel::Path::translation:
        case Channel::Path::scale: return 3;
        case Channel::Path::rotation: return 4;
        case Channel::Path::weights: break;
    }
    const tinygltf::Node& n = src.model->nodes[size_t(node)];
    if (n.mesh < 0 || size_t(n.mesh) >= src.model->meshes.size() ||
        src.model->meshes[size_t(n.mesh)].primitives.empty())
        src.fail(where + ": 'weights' channel on node " + std::to_string(node) + ", which has no mesh");
    return int(src.model->meshes[size_t(n.mesh)].primitives[0].targets.size());
}

Sampler read_sampler(const Source& src, const tinygltf::AnimationSampler& s, int width,
                     const std::string& where) {
    Sampler out;
    out.width = width;
    if (s.interpolation.empty() || s.interpolation == "LINEAR") out.interpolation = Sampler::Interpolation::linear;
    else if (s.interpolation == "STEP") out.interpolation = Sampler::Interpolation::step;
    else if (s.interpolation == "CUBICSPLINE") out.interpolation = Sampler::Interpolation::cubic_spline;
    else src.fail(where + ": interpolation '" + s.interpolation + "' unknown (LINEAR, STEP, CUBICSPLINE)");
    AccessorView in = view_accessor(src, s.input, where + " input");
    AccessorView values = view_accessor(src, s.output, where + " output");
    if (in.components != 1 || in.count == 0) src.fail(where + ": input must be a non-empty SCALAR accessor");
    for (size_t k = 0; k < in.count; ++k) {
        float t = in.component(k, 0);
        if (!std::isfinite(t)) src.fail(where + ": keyframe time " + std::to_string(k) + " is not finite");
        if (k > 0 && t < out.times.back())
            src.fail(where + ": keyframe times decrease at keyframe " + std::to_string(k));
        out.times.push_back(t);
    }
    const size_t per_key = out.interpolation == Sampler::Interpolation::cubic_spline ? 3 : 1;
    const size_t floats = size_t(values.count) * size_t(values.components);
    if (width <= 0 || floats != in.count * per_key * size_t(width))
        src.fail(where + ": output has " + std::to_string(floats) + " numbers, expected " +
                 std::to_string(in.count * per_key * size_t(std::max(width, 0))) + " (" +
                 std::to_string(in.count) + " keyframes x " + std::to_string(per_key) + " x " +
                 std::to_string(width) + ")");
    out.values.reserve(floats);
    for (size_t i = 0; i < values.count; ++i)
        for (int c = 0; c < values.components; ++c) {
            float v = values.component(i, c);
            if (!std::isfinite(v)) src.fail(where + ": output value " + std::to_string(i) + " is not finite");
            out.values.push_back(v);
        }
    return out;
}

}  // namespace

void Sampler::sample(double t, bool rotation, float* out) const {
    const size_t n = times.size(), w = size_t(width);
    const bool cubic = interpolation == Interpolation::cubic_spline;
    // The value (not a tangent) of keyframe k.
    auto value = [&](size_t k) { return values.data() + (cubic ? (3 * k + 1) * w : k * w); };
    size_t k = size_t(std::upper_bound(times.begin(), times.end(), float(t)) - times.begin());
    if (k == 0 || k == n) {
        const float* v = value(k == 0 ? 0 : n - 1);
        std::copy(v, v + w, out);
    } else {
        const size_t a = k - 1, b = k;
        const double dt = double(times[b]) - double(times[a]);
        const double u = dt > 0.0 ? (t - times[a]) / dt : 0.0;
        const float* va = value(a);
        const float* vb = value(b);
        if (interpolation == Interpolation::step || dt <= 0.0) {
            std::copy(va, va + w, out);
        } else if (!cubic && rotation) {
            glm::dquat qa(va[3], va[0], va[1], va[2]), qb(vb[3], vb[0], vb[1], vb[2]);
            glm::dquat q = glm::slerp(qa, qb, u);  // shortest path: glm flips qb if dot < 0
            out[0] = float(q.x), out[1] = float(q.y), out[2] = float(q.z), out[3] = float(q.w);
        } else if (!cubic) {
            for (size_t c = 0; c < w; ++c) out[c] = float(va[c] + (double(vb[c]) - va[c]) * u);
        } else {
            const float* out_tangent_a = values.data() + (3 * a + 2) * w;
            const float* in_tangent_b = values.data() + (3 * b) * w;
            const double u2 = u * u, u3 = u2 * u;
            for (size_t c = 0; c < w; ++c)
                out[c] = float((2 * u3 - 3 * u2 + 1) * va[c] + (u3 - 2 * u2 + u) * dt * out_tangent_a[c] +
                               (-2 * u3 + 3 * u2) * vb[c] + (u3 - u2) * dt * in_tangent_b[c]);
        }
    }
    if (rotation) {
        double len = std::sqrt(double(out[0]) * out[0] + double(out[1]) * out[1] +
                               double(out[2]) * out[2] + double(out[3]) * out[3]);
        if (len > 0.0)
            for (int c = 0; c < 4; ++c) out[c] = float(out[c] / len);
    }
}

std::vector<Channel> read_channels(const Source& src) {
    std::vector<Channel> channels;
    const tinygltf::Model& m = *src.model;
    for (size_t a = 0; a < m.animations.size(); ++a) {
        const tinygltf::Animation& anim = m.animations[a];
        const std::string name = element("animation", a, anim.name);
        for (size_t c = 0; c < anim.channels.size(); ++c) {
            const tinygltf::AnimationChannel& ch = anim.channels[c];
            const std::string where = name + " channel " + std::to_string(c);
            if (ch.target_node < 0) continue;  // a channel without a node is ignored (spec 3.11)
            if (size_t(ch.target_node) >= m.nodes.size())
                src.fail(where + ": target node " + std::to_string(ch.target_node) + " out of range");
            Channel out;
            out.node = ch.target_node;
            if (ch.target_path == "translation") out.path = Channel::Path::translation;
            else if (ch.target_path == "rotation") out.path = Channel::Path::rotation;
            else if (ch.target_path == "scale") out.path = Channel::Path::scale;
            else if (ch.target_path == "weights") out.path = Channel::Path::weights;
            else src.fail(where + ": target path '" + ch.target_path + "' unknown");
            if (ch.sampler < 0 || size_t(ch.sampler) >= anim.samplers.size())
                src.fail(where + ": sampler " + std::to_string(ch.sampler) + " out of range");
            const std::string swhere = name + " sampler " + std::to_string(ch.sampler);
            out.sampler = read_sampler(src, anim.samplers[size_t(ch.sampler)],
                                       path_width(src, out.path, out.node, where), swhere);
            channels.push_back(std::move(out));
        }
    }
    return channels;
}

}  // namespace rtsim::gltf
