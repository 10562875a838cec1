#include <gtest/gtest.h>

#include "lidarloop/core/descriptor_config.hpp"
#include "lidarloop/core/error.hpp"

namespace lidarloop::core {
namespace {

TEST(DescriptorConfig, MethodNamesRoundTrip) {
    for (Method method : {Method::kHeight, Method::kRange}) {
        EXPECT_EQ(ParseMethod(ToString(method)), method);
    }
    EXPECT_EQ(ProjectionOf(Method::kHeight), Projection::kHeight);
    EXPECT_EQ(ProjectionOf(Method::kRange), Projection::kRange);
}

TEST(DescriptorConfig, UnknownMethodNamesTheValidOnes) {
    try {
        ParseMethod("sift");
        FAIL() << "accepted an unknown method";
    } catch (const ConfigError& e) {
        EXPECT_NE(std::string(e.what()).find("height, range"), std::string::npos);
    }
}

TEST(DescriptorConfig, ValidateChecksNestedHistogramConfig) {
    DescriptorConfig config;
    EXPECT_NO_THROW(config.Validate());
    config.histogram.bins = 0;
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
