#include <gtest/gtest.h>

#include "lidarloop/core/descriptor_config.hpp"
#include "lidarloop/core/error.hpp"

namespace lidarloop::core {
namespace {

TEST(DescriptorConfig, MethodNamesRoundTrip) {
    for (Method method : {Method::kHeight, Method::kRange, Method::kNdt}) {
        EXPECT_EQ(ParseMethod(ToString(method)), method);
    }
    EXPECT_EQ(ProjectionOf(Method::kHeight), Projection::kHeight);
    EXPECT_EQ(ProjectionOf(Method::kRange), Projection::kRange);
    EXPECT_THROW(ProjectionOf(Method::kNdt), ConfigError);
    EXPECT_TRUE(IsHistogramMethod(Method::kRange));
    EXPECT_FALSE(IsHistogramMethod(Method::kNdt));
}

TEST(DescriptorConfig, UnknownMethodNamesTheValidOnes) {
    try {
        ParseMethod("sift");
        FAIL() << "accepted an unknown method";
    } catch (const ConfigError& e) {
        EXPECT_NE(std::string(e.what()).find("height, range, ndt"), std::string::npos);
    }
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
