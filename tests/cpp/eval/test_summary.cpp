#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/eval/summary.hpp"

namespace lidarloop::eval {
namespace {

TEST(Summary, QuantilesInterpolateLinearly) {
    const std::vector<double> sorted{1.0, 2.0, 3.0, 4.0};
    EXPECT_DOUBLE_EQ(Quantile(sorted, 0.0), 1.0);
    EXPECT_DOUBLE_EQ(Quantile(sorted, 0.25), 1.75);
    EXPECT_DOUBLE_EQ(Quantile(sorted, 0.5), 2.5);
    EXPECT_DOUBLE_EQ(Quantile(sorted, 1.0), 4.0);
    EXPECT_THROW(Quantile(sorted, 1.5), core::Error);
    EXPECT_THROW(Quantile({}, 0.5), core::EmptyInputError);
    const Summary s = Summarize(std::vector<double>{4.0, 1.0, 3.0, 2.0});
    EXPECT_EQ(s.count, 4u);
    EXPECT_DOUBLE_EQ(s.mean, 2.5);
    EXPECT_DOUBLE_EQ(s.min, 1.0);
    EXPECT_DOUBLE_EQ(s.median, 2.5);
    EXPECT_DOUBLE_EQ(s.p95, 3.85);
    EXPECT_DOUBLE_EQ(s.max, 4.0);
    const Summary one = Summarize(std::vector<double>{7.0});
    EXPECT_DOUBLE_EQ(one.p05, 7.0);
    EXPECT_DOUBLE_EQ(one.p95, 7.0);
    EXPECT_THROW(Summarize(std::vector<double>{1.0, std::numeric_limits<double>::infinity()}),
                 core::Error);
}

TEST(Summary, DistinctivenessRatios) {
    const double inf = std::numeric_limits<double>::infinity();
    const std::vector<BestMatch> matches{
        {1, 0.1, 0.4},  // 0.25
        {0, 0.3, 0.3},  // a tie: 1
        {0, 0.0, 0.0},  // 0 / 0 counts as 1
        {0, 0.2, inf},  // no runner-up: skipped
        {},             // no match: skipped
        {0, 0.0, 0.5},  // 0
    };
    const DistinctivenessSummary result = SummarizeDistinctiveness(matches);
    EXPECT_EQ(result.scans, 6u);
    EXPECT_EQ(result.used, 4u);
    ASSERT_TRUE(result.ratio.has_value());
    EXPECT_DOUBLE_EQ(result.ratio->min, 0.0);
    EXPECT_DOUBLE_EQ(result.ratio->max, 1.0);
    EXPECT_DOUBLE_EQ(result.ratio->mean, 2.25 / 4.0);
    EXPECT_DOUBLE_EQ(result.ratio->median, 0.625);
    EXPECT_FALSE(SummarizeDistinctiveness(std::vector<BestMatch>(3)).ratio.has_value());
}

}  // namespace
}  // namespace lidarloop::eval
