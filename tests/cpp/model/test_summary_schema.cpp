// The summary keys are declared once (sim/report/summary_schema.h): a summary with an
// undeclared key, or without a declared one, is refused with the key's name.
#include <gtest/gtest.h>

#include "sim/report/summary_schema.h"
#include "tests/cpp/model/model_test_util.h"
#include "traces/common/error.h"

namespace rtsim {
namespace {

nlohmann::json full_summary(bool sampled) {
    nlohmann::json s = nlohmann::json::object();
    for (const StatDecl& d : summary_stats().stats)
        if (!d.optional || sampled) s[d.key] = nullptr;
    return s;
}

TEST(SummarySchema, ExactlyTheDeclaredKeysPass) {
    EXPECT_NO_THROW(check_summary(full_summary(false), false));
    EXPECT_NO_THROW(check_summary(full_summary(true), true));
}

TEST(SummarySchema, UndeclaredOrMissingKeysAreNamed) {
    nlohmann::json s = full_summary(false);
    s["mrays_per_fortnight"] = 1;
    EXPECT_NE(test::error_of([&] { check_summary(s, false); }).find("'summary.mrays_per_fortnight' is not declared"),
              std::string::npos);
    s = full_summary(false);
    s.erase("cycles");
    EXPECT_NE(test::error_of([&] { check_summary(s, false); }).find("'summary.cycles' is declared but was not written"), std::string::npos);
    // Sampled-only keys are required in sampled runs.
    EXPECT_NE(test::error_of([&] { check_summary(full_summary(false), true); }).find("_ci95"), std::string::npos);
}

TEST(SummarySchema, EveryKeyHasAMeaning) {
    for (const StatDecl& d : summary_stats().stats) EXPECT_GT(std::string(d.meaning).size(), 5u) << d.key;
}

}  // namespace
}  // namespace rtsim
