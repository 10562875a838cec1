#include <gtest/gtest.h>

#include "lidarloop/core/descriptor_config.hpp"
#include "lidarloop/core/error.hpp"

#include <string>

namespace lidarloop::core {
namespace {

TEST(DescriptorConfig, HistogramMethodsAndTheirProjections) {
    EXPECT_EQ(ToString(Method::kRange), "range");
    EXPECT_EQ(ProjectionOf(Method::kHeight), Projection::kHeight);
    EXPECT_EQ(ProjectionOf(Method::kRange), Projection::kRange);
    EXPECT_THROW(ProjectionOf(Method::kNdt), ConfigError);
    EXPECT_TRUE(IsHistogramMethod(Method::kRange));
    EXPECT_FALSE(IsHistogramMethod(Method::kNdt));
}

TEST(DescriptorConfig, AMethodNameHasOneTo31Characters) {
    EXPECT_EQ(Method("rings").name(), "rings");
    EXPECT_THROW(Method(""), ConfigError);
    EXPECT_THROW(Method(std::string(32, 'x')), ConfigError);
    EXPECT_EQ(Method(std::string(31, 'x')).name().size(), 31U);
    EXPECT_FALSE(Method("range") == Method("ranges"));
}

TEST(DescriptorConfig, ValidateChecksNestedHistogramConfig) {
    DescriptorConfig config;
    EXPECT_NO_THROW(config.Validate());
    config.histogram.bins = 0;
    EXPECT_THROW(config.Validate(), ConfigError);
    config.histogram.bins = 10;
    config.ndt.cell_size_m = -1.0;
    EXPECT_THROW(config.Validate(), ConfigError);
}

TEST(DescriptorConfig, OutOfRangePolicyNamesRoundTrip) {
    EXPECT_EQ(ParseOutOfRangePolicy("clamp"), OutOfRangePolicy::kClamp);
    EXPECT_EQ(ParseOutOfRangePolicy("drop"), OutOfRangePolicy::kDrop);
    EXPECT_EQ(ToString(OutOfRangePolicy::kDrop), "drop");
    EXPECT_THROW(ParseOutOfRangePolicy("wrap"), ConfigError);
}

}  // namespace
}  // namespace lidarloop::core
