// Spatial splits of the SBVH builder (sbvh_builder.h): Stich, Friedrich & Dietrich 2009,
// "Spatial splits in bounding volume hierarchies", sections 4.3 (binning with triangle clipping)
// and 4.4 (reference unsplitting).
#include <algorithm>
#include <optional>
#include <vector>

#include "traces/bvh/sbvh_builder_impl.h"
#include "traces/bvh/sbvh_clip.h"

namespace rtsim {
namespace sbvh_detail {
namespace {

/// Bin planes of one axis: planes[k] = lo + k * width, the last one the box's hi, strictly
/// increasing (checked by the caller). Bins are closed on the left: x is in the last bin whose
/// plane is <= x.
struct SpatialBins {
    const float* planes;
    uint32_t count;
    float lo, inv_width;

    uint32_t estimate(float x) const {
        const float f = std::min(std::max((x - lo) * inv_width, 0.0f), float(count - 1));
        return uint32_t(f);
    }
    /// The bin a box starting at x enters: the last bin whose plane is <= x.
    uint32_t first(float x) const {
        uint32_t k = estimate(x);
        while (k > 0 && planes[k] > x) --k;
        while (k + 1 < count && planes[k + 1] <= x) ++k;
        return k;
    }
    /// The bin a box ending at x (and starting in bin `from`) leaves: the last one whose plane is < x.
    uint32_t last(float x, uint32_t from) const {
        uint32_t k = estimate(x);
        while (k > 0 && planes[k] >= x) --k;
        while (k + 1 < count && planes[k + 1] < x) ++k;
        return std::max(k, from);
    }
};

}  // namespace

// Spatial-split binning (section 4.3), all three axes in one pass: a reference inside one bin
// grows it whole; one spanning several is clipped into each (its triangle clipped to its box
// once, then chopped along each axis it spans), grows each with its piece's box, and counts as
// entering its first non-empty bin and leaving its last ("chopped binning").
void SbvhBuilder::bin_spatial(const std::vector<Ref>& refs, const std::vector<float>* planes, const bool* usable) {
    const uint32_t nb = m_s.spatial_bins;
    SpatialBins bins[3];
    for (int a = 0; a < 3; ++a)
        if (usable[a]) bins[a] = {planes[a].data(), nb, planes[a][0], float(nb) / (planes[a][nb] - planes[a][0])};
    m_sbox.assign(3 * size_t(nb), Aabb{});
    m_entry.assign(3 * size_t(nb), 0);
    m_exit.assign(3 * size_t(nb), 0);
    m_pieces.resize(nb);
    for (const Ref& r : refs) {
        std::optional<ClippedTriangle> clipped;  // made once, for the first axis that needs it
        for (int a = 0; a < 3; ++a) {
            if (!usable[a]) continue;
            Aabb* sbox = &m_sbox[a * size_t(nb)];
            const uint32_t b0 = bins[a].first(r.box.lo[a]), b1 = bins[a].last(r.box.hi[a], b0);
            uint32_t in = b0, out = b1;
            if (b0 == b1) {
                sbox[b0].grow(r.box);
            } else {
                if (!clipped) clipped.emplace(m_tris[r.prim], r.box);
                clipped->chop(a, &planes[a][b0], b1 - b0 + 1, m_pieces.data());
                in = b1, out = b0;
                for (uint32_t b = b0; b <= b1; ++b) {
                    if (m_pieces[b - b0].empty()) continue;
                    sbox[b].grow(m_pieces[b - b0]);
                    in = std::min(in, b), out = std::max(out, b);
                }
                if (in > out) in = b0, out = b0, sbox[b0].grow(r.box);  // nothing left: keep it whole
            }
            ++m_entry[a * size_t(nb) + in];
            ++m_exit[a * size_t(nb) + out];
        }
    }
}

Candidate SbvhBuilder::spatial_split(const std::vector<Ref>& refs, const Aabb& box, uint64_t budget) {
    const uint32_t nb = m_s.spatial_bins;
    const uint64_t n = refs.size();
    std::vector<float> planes[3];
    bool usable[3];
    for (int a = 0; a < 3; ++a) {
        planes[a].resize(nb + 1);
        const float width = (box.hi[a] - box.lo[a]) / float(nb);
        for (uint32_t k = 0; k < nb; ++k) planes[a][k] = box.lo[a] + float(k) * width;
        planes[a][nb] = box.hi[a];
        usable[a] = width > 0.0f;  // and no room for bins at this scale if planes coincide:
        for (uint32_t k = 0; k < nb && usable[a]; ++k) usable[a] = planes[a][k] < planes[a][k + 1];
    }
    bin_spatial(refs, planes, usable);
    m_rbox.resize(nb);
    m_rcount.resize(nb);
    Candidate best;
    for (int a = 0; a < 3; ++a) {
        if (!usable[a]) continue;
        const Aabb* sbox = &m_sbox[a * size_t(nb)];
        const uint32_t *entry = &m_entry[a * size_t(nb)], *exit = &m_exit[a * size_t(nb)];
        Aabb acc;
        uint32_t count = 0;
        for (uint32_t b = nb - 1; b > 0; --b) {
            acc.grow(sbox[b]);
            count += exit[b];
            m_rbox[b] = acc;
            m_rcount[b] = count;
        }
        acc = Aabb{};
        count = 0;
        for (uint32_t b = 1; b < nb; ++b) {
            acc.grow(sbox[b - 1]);
            count += entry[b - 1];
            const uint64_t nl = count, nr = m_rcount[b];
            // Both sides smaller than the node (progress) and the duplicates within budget.
            if (nl == 0 || nr == 0 || nl >= n || nr >= n || nl + nr - n > budget) continue;
            const float cost = acc.half_area() * float(nl) + m_rbox[b].half_area() * float(nr);
            if (cost < best.cost)
                best = Candidate{Candidate::spatial, a, cost, acc, m_rbox[b], uint32_t(nl), uint32_t(nr), 0, 0, 0,
                                 planes[a][b]};
        }
    }
    return best;
}

// Splits the references at the chosen plane: those on one side go there, straddlers are split
// by clipping or, where the SAH prefers it, kept whole on one side (unsplitting, section 4.4).
bool SbvhBuilder::apply_spatial(const Item& item, Candidate c, std::vector<Ref>* l, std::vector<Ref>* r) {
    const int a = c.axis;
    const float s = c.plane;
    float nl = float(c.left_count), nr = float(c.right_count);
    uint64_t unsplit = 0;
    for (const Ref& ref : item.refs) {
        if (ref.box.hi[a] <= s) {
            l->push_back(ref);
            continue;
        }
        if (ref.box.lo[a] >= s) {
            r->push_back(ref);
            continue;
        }
        Aabb lb, rb;
        ClippedTriangle(m_tris[ref.prim], ref.box).split(a, s, &lb, &rb);
        if (lb.empty() || rb.empty()) {  // the triangle itself lies on one side
            if (lb.empty() && rb.empty()) l->push_back(ref);  // (never: kept whole, conservatively)
            else (lb.empty() ? r : l)->push_back(Ref{lb.empty() ? rb : lb, ref.prim});
            continue;
        }
        if (m_s.unsplit) {
            const float split = c.left.half_area() * nl + c.right.half_area() * nr;
            const float to_left = joined(c.left, ref.box).half_area() * nl + c.right.half_area() * std::max(nr - 1, 1.0f);
            const float to_right = c.left.half_area() * std::max(nl - 1, 1.0f) + joined(c.right, ref.box).half_area() * nr;
            if (to_left < split && to_left <= to_right) {
                l->push_back(ref), c.left.grow(ref.box), nr = std::max(nr - 1, 1.0f), ++unsplit;
                continue;
            }
            if (to_right < split) {
                r->push_back(ref), c.right.grow(ref.box), nl = std::max(nl - 1, 1.0f), ++unsplit;
                continue;
            }
        }
        l->push_back(Ref{lb, ref.prim});
        r->push_back(Ref{rb, ref.prim});
    }
    const size_t n = item.refs.size();
    const bool ok = !l->empty() && !r->empty() && l->size() < n && r->size() < n &&
                    l->size() + r->size() - n <= item.budget && fits_depth(item.depth, std::max(l->size(), r->size()));
    if (ok) m_stats.unsplit += unsplit;
    return ok;
}

}  // namespace sbvh_detail
}  // namespace rtsim
