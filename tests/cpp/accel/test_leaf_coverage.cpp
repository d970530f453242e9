// LeafCoverage, the check that every triangle of a BVH or BIH image is in exactly one leaf.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "traces/accel/leaf_coverage.h"

namespace rtsim {
namespace {

const auto kFail = [](const std::string& what) { throw std::runtime_error(what); };

std::string refusal(void (*steps)(LeafCoverage&)) {
    LeafCoverage c(6);
    try {
        steps(c);
        c.finish(kFail);
    } catch (const std::runtime_error& e) {
        return e.what();
    }
    return "";
}

TEST(LeafCoverage, AcceptsEveryTriangleInOneLeaf) {
    EXPECT_EQ(refusal([](LeafCoverage& c) {
                  c.add(0, 4, kFail, [] { return std::string("leaf a"); });
                  c.add(4, 2, kFail, [] { return std::string("leaf b"); });
              }),
              "");
}

TEST(LeafCoverage, NamesTheCulprit) {
    EXPECT_EQ(
        refusal([](LeafCoverage& c) { c.add(4, 3, kFail, [] { return std::string("node 7 slot 2"); }); }),
        "node 7 slot 2 references triangles 4..6 of 6");
    EXPECT_EQ(refusal([](LeafCoverage& c) {
                  c.add(0, 4, kFail, [] { return std::string("a"); });
                  c.add(3, 3, kFail, [] { return std::string("b"); });
              }),
              "triangle 3 is in two leaves");
    EXPECT_EQ(refusal([](LeafCoverage& c) { c.add(0, 5, kFail, [] { return std::string("a"); }); }),
              "triangle 5 is in no leaf (unreachable)");
}

}  // namespace
}  // namespace rtsim
