// Triangle clipping for spatial splits (sbvh_clip.h).
#include "traces/bvh/sbvh_clip.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rtsim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// Largest float <= x and smallest float >= x.
float round_down(double x) {
    float f = float(x);
    return double(f) > x ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}
float round_up(double x) {
    float f = float(x);
    return double(f) < x ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

}  // namespace

ClippedTriangle::ClippedTriangle(const Triangle& tri, const Aabb& box) : m_box(box) {
    const Vec3* v[3] = {&tri.v0, &tri.v1, &tri.v2};
    double magnitude = 0.0;
    Polygon p;
    p.n = 3;
    for (int i = 0; i < 3; ++i)
        for (int a = 0; a < 3; ++a) {
            p.v[i][a] = double((*v[i])[a]);
            magnitude = std::max(magnitude, std::fabs(p.v[i][a]));
        }
    // Each clipped coordinate is a + t (b - a) with |a|, |b| <= magnitude: a few double roundings
    // per clip, a few clips. 2^-40 x magnitude bounds that error with a wide margin and is still
    // far below a float ulp of the coordinates, so boxes grow by at most one float ulp.
    m_margin = magnitude * 0x1p-40;
    Polygon q;
    for (int a = 0; a < 3; ++a) {
        clip(p, a, double(box.lo[a]), 1.0, &q);
        clip(q, a, double(box.hi[a]), -1.0, &p);
    }
    m_poly = p;
}

double ClippedTriangle::area() const {
    double c[3] = {0.0, 0.0, 0.0};  // twice the vector area: sum of v_i x v_(i+1)
    for (int i = 0; i < m_poly.n; ++i) {
        const double* a = m_poly.v[i];
        const double* b = m_poly.v[(i + 1) % m_poly.n];
        c[0] += a[1] * b[2] - a[2] * b[1];
        c[1] += a[2] * b[0] - a[0] * b[2];
        c[2] += a[0] * b[1] - a[1] * b[0];
    }
    return 0.5 * std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
}

void ClippedTriangle::clip(const Polygon& in, int axis, double position, double sign, Polygon* out) {
    out->n = 0;
    for (int i = 0; i < in.n; ++i) {
        const double* a = in.v[i];
        const double* b = in.v[(i + 1) % in.n];
        const double da = sign * (a[axis] - position), db = sign * (b[axis] - position);
        if (da >= 0.0 && out->n < kMaxVertices) std::copy(a, a + 3, out->v[out->n++]);
        if ((da >= 0.0) != (db >= 0.0) && out->n < kMaxVertices) {
            // The edge crosses the plane: its crossing point, exactly on the plane along axis.
            const double t = da / (da - db);
            double* p = out->v[out->n++];
            for (int k = 0; k < 3; ++k) p[k] = a[k] + t * (b[k] - a[k]);
            p[axis] = position;
        }
    }
}

Aabb ClippedTriangle::conservative_box(const Polygon& p, int axis, float lo, float hi) const {
    double bl[3] = {kInf, kInf, kInf}, bh[3] = {-kInf, -kInf, -kInf};
    const Polygon* src = &p;
    if (m_poly.n == 0) {
        // The triangle's part in the reference box vanished in double (a sliver on the box's
        // boundary): the reference box itself, cut to the slab, stands for it.
        Aabb box = m_box;
        box.lo[axis] = std::max(box.lo[axis], lo);
        box.hi[axis] = std::min(box.hi[axis], hi);
        return box.empty() ? Aabb{} : box;
    }
    if (p.n == 0) {
        // Empty in double, but the exact piece may still be a sliver within the clipping error
        // of the slab: then the whole polygon's box (cut to the slab below) stands for it.
        double pl = kInf, ph = -kInf;
        for (int i = 0; i < m_poly.n; ++i) {
            pl = std::min(pl, m_poly.v[i][axis]);
            ph = std::max(ph, m_poly.v[i][axis]);
        }
        if (pl - m_margin > double(hi) || ph + m_margin < double(lo)) return Aabb{};
        src = &m_poly;
    }
    for (int i = 0; i < src->n; ++i)
        for (int a = 0; a < 3; ++a) {
            bl[a] = std::min(bl[a], src->v[i][a]);
            bh[a] = std::max(bh[a], src->v[i][a]);
        }
    Aabb box;
    for (int a = 0; a < 3; ++a) {
        box.lo[a] = std::max(round_down(bl[a] - m_margin), m_box.lo[a]);
        box.hi[a] = std::min(round_up(bh[a] + m_margin), m_box.hi[a]);
    }
    box.lo[axis] = std::max(box.lo[axis], lo);
    box.hi[axis] = std::min(box.hi[axis], hi);
    return box.empty() ? Aabb{} : box;
}

void ClippedTriangle::chop(int axis, const float* planes, uint32_t count, Aabb* out) const {
    Polygon rest, piece, next;
    clip(m_poly, axis, double(planes[0]), 1.0, &rest);
    for (uint32_t k = 0; k < count; ++k) {
        const double s = double(planes[k + 1]);
        clip(rest, axis, s, -1.0, &piece);
        clip(rest, axis, s, 1.0, &next);
        out[k] = conservative_box(piece, axis, planes[k], planes[k + 1]);
        rest = next;
    }
}

void ClippedTriangle::split(int axis, float position, Aabb* left, Aabb* right) const {
    Polygon part;
    clip(m_poly, axis, double(position), -1.0, &part);
    *left = conservative_box(part, axis, -std::numeric_limits<float>::infinity(), position);
    clip(m_poly, axis, double(position), 1.0, &part);
    *right = conservative_box(part, axis, position, std::numeric_limits<float>::infinity());
}

}  // namespace rtsim
