// Round trips every scan writer must pass, written once; test_pcd.cpp and test_ply.cpp instantiate
// them (ScanRoundTrip in io_test_utils.hpp) with each of their encodings.
#include <cmath>
#include <cstddef>
#include <limits>

#include <gtest/gtest.h>

#include "io/io_test_utils.hpp"

namespace lidarloop::io {
namespace {

using core::PointCloud;
using test::ExpectSameCloud;
using test::ScanRoundTrip;

TEST_P(ScanRoundTrip, RandomCloudIsExact) {
    const PointCloud cloud = test::RandomCloud(2000, 7);
    ExpectSameCloud(RoundTrip(cloud), cloud);
}

TEST_P(ScanRoundTrip, NanPointsSurvive) {
    PointCloud cloud = test::RandomCloud(300, 8);
    for (std::size_t i = 0; i < cloud.size(); i += 3)
        cloud[i] = {test::kNanFloat, test::kNanFloat, test::kNanFloat};
    const PointCloud read = RoundTrip(cloud);
    ExpectSameCloud(read, cloud);
    EXPECT_TRUE(std::isnan(read[0].x()));
    EXPECT_FALSE(std::isnan(read[1].x()));
}

TEST_P(ScanRoundTrip, EmptyCloudStaysEmpty) { EXPECT_TRUE(RoundTrip({}).empty()); }

TEST_P(ScanRoundTrip, ExtremeValuesAreExact) {
    using Limits = std::numeric_limits<float>;
    const PointCloud cloud = {{Limits::denorm_min(), Limits::min(), Limits::max()},
                              {Limits::lowest(), -0.0f, 0.0f},
                              {0.1f, 1.0f / 3.0f, -16777215.0f},
                              {Limits::infinity(), -Limits::infinity(), 123456.789f},
                              {std::nextafter(1.0f, 2.0f), -1e-38f, 3.4e38f}};
    ExpectSameCloud(RoundTrip(cloud), cloud);
}

}  // namespace
}  // namespace lidarloop::io
