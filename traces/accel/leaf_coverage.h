#pragma once
// Every triangle of an image in exactly one leaf, checked as a validation pass meets the leaves
// of a BVH or a BIH. (The space-partitioning structures list a triangle in every cell it
// overlaps; they check their lists instead, listed_regions.h.)
#include <cstdint>
#include <string>
#include <vector>

namespace rtsim {

class LeafCoverage {
public:
    explicit LeafCoverage(uint64_t triangles) : m_covered(triangles, 0) {}

    /// Marks triangles [first, first + count) as the leaf that `leaf()` names references them.
    /// `fail(message)` throws; the messages are built only on failure.
    template <class Fail, class Name>
    void add(uint64_t first, uint64_t count, const Fail& fail, const Name& leaf) {
        const uint64_t n = m_covered.size();
        if (first + count > n)
            fail(leaf() + " references triangles " + std::to_string(first) + ".." +
                 std::to_string(first + count - 1) + " of " + std::to_string(n));
        for (uint64_t k = first; k < first + count; ++k) {
            if (m_covered[k]) fail("triangle " + std::to_string(k) + " is in two leaves");
            m_covered[k] = 1;
        }
    }
    /// Fails on the first triangle that no leaf references.
    template <class Fail>
    void finish(const Fail& fail) const {
        for (uint64_t k = 0; k < m_covered.size(); ++k)
            if (!m_covered[k]) fail("triangle " + std::to_string(k) + " is in no leaf (unreachable)");
    }

private:
    std::vector<uint8_t> m_covered;
};

}  // namespace rtsim
