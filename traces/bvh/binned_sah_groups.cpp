// Grouping a node's references by bin for the SAH sweep (binned_sah_builder.cpp,
// NodeSplitter::find_sah_split): the filled bins of each axis in increasing order, each with the
// box its references grow to in range order, their count and the bin index. How they are found
// depends on the node's size (binning, ranking, a pair), never what they are: every way gives
// the boxes the plain binning pass gives, bit for bit.
#include <algorithm>
#include <cstring>

#include "traces/bvh/binned_sah_impl.h"

namespace rtsim {
namespace binned_detail {
namespace {

// Calls fn(axis, bin) for each non-zero count, bins in increasing order, axis by axis. The
// counts are tested four at a time; a node's few filled bins then cost a bit scan each.
template <class Fn>
void for_each_filled(const uint32_t* counts, uint32_t stride, const Fn& fn) {
    for (uint32_t a = 0; a < 3; ++a)
        for (uint32_t word = 0; word < stride; word += 64) {
            uint64_t m = 0;
            for (uint32_t b = word; b < std::min(stride, word + 64); b += 4) {
                Int4 c;
                std::memcpy(&c, counts + a * stride + b, sizeof c);
                const Int4 nz = c != Int4{0, 0, 0, 0};  // -1 where non-zero
                m |= uint64_t((nz[0] & 1) | (nz[1] & 2) | (nz[2] & 4) | (nz[3] & 8)) << (b - word);
            }
            for (; m; m &= m - 1) fn(a, word + uint32_t(__builtin_ctzll(m)));
        }
}

}  // namespace

// Bins the range's references into m_bins, then moves the filled bins to the groups (emptying
// the bins for the next node). A long range is binned as two halves interleaved, the second into
// m_bins2, then merged into m_bins: consecutive references of a mesh tend to fall into the same
// bins, and two streams halve the chains of dependent updates of one bin. The merge is exact:
// min(a, b) = a < b ? a : b returns the later operand on ties (-0 == +0), so min(min over the
// first half, min over the second) is bit for bit the min over the whole range in order
// (likewise max).
void NodeSplitter::group_by_bins(uint32_t begin, uint32_t end, const BinMapper& map) {
    const uint32_t stride = m_stride;
    auto bin = [&map, stride](const PrimRef& r, Box* bins, uint32_t* counts) {
        const Float4 lo = r.lo3();
        const Int4 index = map(r) + Int4{0, int32_t(stride), 2 * int32_t(stride), 0};
        for (uint32_t a = 0; a < 3; ++a) {
            bins[index[a]].grow(lo, r.hi);
            ++counts[index[a]];
        }
    };
    constexpr uint32_t kTwoStreams = 64;  // shorter ranges: the merge would cost more than it saves
    if (end - begin < kTwoStreams) {
        for (uint32_t i = begin; i < end; ++i) bin(m_refs[i], m_bins.data(), m_counts.data());
    } else {
        const uint32_t half = (end - begin) / 2, mid = begin + half;
        for (uint32_t i = 0; i < half; ++i) {
            bin(m_refs[begin + i], m_bins.data(), m_counts.data());
            bin(m_refs[mid + i], m_bins2.data(), m_counts2.data());
        }
        if ((end - begin) & 1) bin(m_refs[end - 1], m_bins2.data(), m_counts2.data());
        for_each_filled(m_counts2.data(), stride, [&](uint32_t a, uint32_t b) {
            const size_t at = a * size_t(stride) + b;
            m_bins[at].grow(m_bins2[at]);
            m_counts[at] += m_counts2[at];
            m_bins2[at] = Box{};
            m_counts2[at] = 0;
        });
    }
    m_groups[0] = m_groups[1] = m_groups[2] = 0;
    for_each_filled(m_counts.data(), stride, [&](uint32_t a, uint32_t b) {
        const size_t at = a * size_t(stride) + b, to = a * size_t(stride) + m_groups[a]++;
        m_group_box[to] = m_bins[at];
        m_group_count[to] = m_counts[at];
        m_group_bin[to] = b;
        m_bins[at] = Box{};
        m_counts[at] = 0;
    });
}

// The groups of a small range without bins: per axis, the references ordered by bin (stably, so
// in range order within a bin) and each run of one bin grown in that order, which is how its bin
// would have grown. Branch-free (ranks by counting, runs by selects): the order is data.
void NodeSplitter::group_small(uint32_t begin, uint32_t end, const BinMapper& map, const bool* usable) {
    const uint32_t n = end - begin;
    // Keys bin * 16 + position (distinct; in bin, then range order) and their ranks, for the
    // three axes at once in the lanes.
    Int4 key[kSmallNode], rank[kSmallNode];
    for (uint32_t k = 0; k < n; ++k) {
        key[k] = map(m_refs[begin + k]) * 16 + int32_t(k);
        rank[k] = Int4{0, 0, 0, 0};
    }
    for (uint32_t k = 0; k < n; ++k)
        for (uint32_t j = 0; j < n; ++j) rank[k] += key[j] < key[k];  // a true lane is -1
    for (uint32_t a = 0; a < 3; ++a) {
        m_groups[a] = 0;
        if (!usable[a]) continue;
        uint32_t sorted[kSmallNode];
        for (uint32_t k = 0; k < n; ++k) sorted[-rank[k][a]] = uint32_t(key[k][a]);
        const size_t base = a * size_t(m_stride);
        Box run;
        uint32_t g = 0, run_count = 0, prev = ~0u;
        for (uint32_t i = 0; i < n; ++i) {
            const PrimRef& r = m_refs[begin + (sorted[i] & 15)];
            const uint32_t b = sorted[i] >> 4, same = uint32_t(b == prev), keep = 0u - same;
            g += 1 - same;
            const Int4 keep4 = Int4{int32_t(keep), int32_t(keep), int32_t(keep), int32_t(keep)};
            run.lo = Float4((Int4(run.lo) & keep4) | (Int4(Box{}.lo) & ~keep4));
            run.hi = Float4((Int4(run.hi) & keep4) | (Int4(Box{}.hi) & ~keep4));
            run.grow(r.lo3(), r.hi);
            run_count = (run_count & keep) + 1;
            m_group_box[base + g - 1] = run;
            m_group_count[base + g - 1] = run_count;
            m_group_bin[base + g - 1] = b;
            prev = b;
        }
        m_groups[a] = g;
    }
}

// A node of two references, the commonest (half the nodes split): where their bins differ on a
// usable axis there are two groups and one boundary, the same on every such axis, so the sweep's
// answer is the first such axis, priced as the sweep prices it.
Split NodeSplitter::split_pair(uint32_t begin, const BinMapper& map, const bool* usable) {
    const PrimRef* r = m_refs + begin;
    const Int4 bin[2] = {map(r[0]), map(r[1])};
    m_groups[0] = m_groups[1] = m_groups[2] = 0;
    for (int a = 0; a < 3; ++a) {
        if (!usable[a] || bin[0][a] == bin[1][a]) continue;
        const int low = bin[0][a] < bin[1][a] ? 0 : 1;
        const size_t base = a * size_t(m_stride);
        for (int g = 0; g < 2; ++g) {
            const PrimRef& p = r[g == 0 ? low : 1 - low];
            m_group_box[base + g] = Box{};
            m_group_box[base + g].grow(p.lo3(), p.hi);
            m_group_count[base + g] = 1;
            m_group_bin[base + g] = uint32_t(bin[g == 0 ? low : 1 - low][a]);
        }
        m_groups[a] = 2;
        const float right = m_group_box[base + 1].half_area_nonempty();
        return Split{a, m_group_bin[base] + 1, m_group_box[base].half_area_nonempty() * 1.0f + right * 1.0f};
    }
    return Split{};
}

}  // namespace binned_detail
}  // namespace rtsim
