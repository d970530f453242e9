// The reduced-precision box test (traces/isect/ray_box_rp.h) is conservative: on random rays and
// boxes, near-degenerate ones included (zero and signed-zero directions, origins on slab planes,
// flat boxes, far origins), every box the fp32 test accepts it accepts too, with an entry
// distance never larger; fewer bits never accept less; its rounding brackets the value.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "isect_test_util.h"
#include "traces/isect/ray_box.h"
#include "traces/isect/ray_box_rp.h"

namespace rtsim {
namespace {

using test::make_ray;

TEST(ReducedPrecisionBox, RoundingBracketsAndLandsOnTheGrid) {
    Rng rng(5);
    for (int i = 0; i < 20000; ++i) {
        const double x = (rng.next() - 0.5) * std::ldexp(1.0, int(rng.next() * 60) - 30);
        for (uint32_t bits : {1u, 4u, 8u, 12u, 22u}) {
            const double lo = round_mantissa(x, bits, false), hi = round_mantissa(x, bits, true);
            ASSERT_LE(lo, x);
            ASSERT_GE(hi, x);
            // On the grid: rounding again changes nothing.
            ASSERT_EQ(round_mantissa(lo, bits, true), lo);
            ASSERT_EQ(round_mantissa(hi, bits, false), hi);
            ASSERT_LE(hi - lo, std::fabs(x) * std::ldexp(1.0, 1 - int(bits)));
        }
    }
    EXPECT_EQ(round_mantissa(0.0, 4, true), 0.0);
    EXPECT_TRUE(std::isinf(round_mantissa(std::numeric_limits<double>::infinity(), 4, false)));
}

/// A random value on a small grid now and then (so origins land on planes), else continuous.
float coordinate(Rng& rng, float scale) {
    if (rng.next() < 0.2f) return std::round(rng.next() * 8.0f - 4.0f) * 0.25f * scale;
    return (rng.next() * 2.0f - 1.0f) * scale;
}

TEST(ReducedPrecisionBox, AcceptsEveryBoxTheFp32TestAccepts) {
    Rng rng(11);
    long fp32_hits = 0, extra = 0;
    for (int i = 0; i < 200000; ++i) {
        const float scale = std::ldexp(1.0f, int(rng.next() * 16) - 6);
        float lo[3], hi[3];
        Vec3 o, d;
        for (int a = 0; a < 3; ++a) {
            const float u = coordinate(rng, scale), v = rng.next() < 0.05f ? u : coordinate(rng, scale);
            lo[a] = std::min(u, v), hi[a] = std::max(u, v);
            o[a] = rng.next() < 0.1f ? lo[a] : coordinate(rng, scale * (rng.next() < 0.1f ? 1000.0f : 2.0f));
            d[a] = rng.next() < 0.08f ? (rng.next() < 0.5f ? 0.0f : -0.0f) : coordinate(rng, 1.0f);
        }
        if (d == Vec3(0.0f)) d.x = 1.0f;
        const float tmin = rng.next() < 0.3f ? rng.next() * scale : 0.0f;
        const float tmax = rng.next() < 0.5f ? tmin + rng.next() * 4.0f * scale : std::numeric_limits<float>::infinity();
        const RayBoxPre pre = ray_box_precompute(make_ray(o, d, tmin, tmax));
        float t32 = 0.0f;
        const bool hit32 = intersect_box(pre, lo, hi, tmin, tmax, &t32);
        fp32_hits += hit32;
        bool finer = hit32;  // what the previous (finer) width accepted
        for (uint32_t bits : {22u, 16u, 12u, 8u, 6u, 4u, 2u, 1u}) {
            float t = 0.0f;
            const bool hit = intersect_box_rp(pre, lo, hi, tmin, tmax, bits, &t);
            ASSERT_TRUE(hit || !finer) << "iteration " << i << ", " << bits << " bits rejects what a finer test accepts";
            if (hit32) {
                ASSERT_LE(t, t32) << "iteration " << i << ", " << bits << " bits";
            }
            extra += hit && !hit32;
            finer = hit;
        }
    }
    // The property is not vacuous: many boxes hit, and the narrower tests accept some more.
    EXPECT_GT(fp32_hits, 2000);
    EXPECT_GT(extra, 1000);
}

}  // namespace
}  // namespace rtsim
