// Triangle clipping for spatial splits (sbvh_clip.h).
#include "traces/bvh/sbvh_clip.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "traces/common/float_rounding.h"

namespace rtsim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

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

struct ClippedTriangle::DBox {
    double lo[3] = {kInf, kInf, kInf}, hi[3] = {-kInf, -kInf, -kInf};
    void grow(const double* p) {
        for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
    }
    bool empty() const { return lo[0] > hi[0]; }
};

void ClippedTriangle::grow_crossings(int axis, double s, DBox* a, DBox* b) const {
    // Where the polygon's edges cross the plane (strictly: an end on the plane is a vertex).
    for (int i = 0; i < m_poly.n; ++i) {
        const double* p = m_poly.v[i];
        const double* q = m_poly.v[(i + 1) % m_poly.n];
        if (!((p[axis] < s && q[axis] > s) || (p[axis] > s && q[axis] < s))) continue;
        const double t = (s - p[axis]) / (q[axis] - p[axis]);
        double x[3];
        for (int k = 0; k < 3; ++k) x[k] = p[k] + t * (q[k] - p[k]);
        x[axis] = s;
        a->grow(x);
        if (b) b->grow(x);
    }
}

Aabb ClippedTriangle::conservative_box(const DBox& piece, int axis, float lo, float hi) const {
    const DBox* src = &piece;
    DBox whole;
    if (m_poly.n == 0) {
        // The triangle's part in the reference box vanished in double (a sliver on the box's
        // boundary): the reference box itself, cut to the slab, stands for it.
        Aabb box = m_box;
        box.lo[axis] = std::max(box.lo[axis], lo);
        box.hi[axis] = std::min(box.hi[axis], hi);
        return box.empty() ? Aabb{} : box;
    }
    if (piece.empty()) {
        // Empty in double, but the exact piece may still be a sliver within the clipping error
        // of the slab: then the whole polygon's box (cut to the slab below) stands for it.
        for (int i = 0; i < m_poly.n; ++i) whole.grow(m_poly.v[i]);
        if (whole.lo[axis] - m_margin > double(hi) || whole.hi[axis] + m_margin < double(lo)) return Aabb{};
        src = &whole;
    }
    Aabb box;
    for (int a = 0; a < 3; ++a) {
        box.lo[a] = std::max(round_down(src->lo[a] - m_margin), m_box.lo[a]);
        box.hi[a] = std::min(round_up(src->hi[a] + m_margin), m_box.hi[a]);
    }
    box.lo[axis] = std::max(box.lo[axis], lo);
    box.hi[axis] = std::min(box.hi[axis], hi);
    return box.empty() ? Aabb{} : box;
}

// A convex polygon's part in a slab is the hull of its vertices in the slab and its edges'
// crossings of the slab's two planes, so each piece's box comes from those points: one pass
// over the edges per plane, no polygon is copied. Binning only prices candidate splits, so the
// boxes are rounded to nearest here; the references a split makes come from split().
void ClippedTriangle::chop(int axis, const float* planes, uint32_t count, Aabb* out) const {
    DBox at_low;  // crossings of the current slab's low plane
    grow_crossings(axis, double(planes[0]), &at_low, nullptr);
    for (uint32_t k = 0; k < count; ++k) {
        const double lo = double(planes[k]), hi = double(planes[k + 1]);
        DBox piece = at_low, at_high;
        for (int i = 0; i < m_poly.n; ++i)
            if (m_poly.v[i][axis] >= lo && m_poly.v[i][axis] <= hi) piece.grow(m_poly.v[i]);
        grow_crossings(axis, hi, &piece, &at_high);
        // An estimate for pricing splits only: nearest rounding, no margin (split() is exact).
        out[k] = Aabb{};
        if (!piece.empty())
            for (int a = 0; a < 3; ++a) out[k].lo[a] = float(piece.lo[a]), out[k].hi[a] = float(piece.hi[a]);
        at_low = at_high;
    }
}

void ClippedTriangle::split(int axis, float position, Aabb* left, Aabb* right) const {
    const double s = double(position);
    DBox l, r;
    for (int i = 0; i < m_poly.n; ++i) {
        if (m_poly.v[i][axis] <= s) l.grow(m_poly.v[i]);
        if (m_poly.v[i][axis] >= s) r.grow(m_poly.v[i]);
    }
    grow_crossings(axis, s, &l, &r);
    *left = conservative_box(l, axis, -std::numeric_limits<float>::infinity(), position);
    *right = conservative_box(r, axis, position, std::numeric_limits<float>::infinity());
}

}  // namespace rtsim
