// The method registry and what every method answers through DescriptorMethod.
#include <cmath>

#include <gtest/gtest.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/pipeline/descriptor_database.hpp"
#include "lidarloop/pipeline/descriptor_method.hpp"
#include "lidarloop/pipeline/histogram_method.hpp"
#include "lidarloop/pipeline/loop_detector.hpp"
#include "lidarloop/pipeline/ndt_method.hpp"
#include "test_utils.hpp"

namespace lidarloop::pipeline {
namespace {

std::string ErrorOf(const std::function<void()>& action) {
    try {
        action();
    } catch (const core::ConfigError& e) {
        return e.what();
    }
    return "no error";
}

TEST(DescriptorMethod, TheBuiltInMethodsComeFirstAndTheirNamesRoundTrip) {
    const std::vector<std::string> names = MethodNames();
    ASSERT_GE(names.size(), 3U);
    EXPECT_EQ(std::vector<std::string>(names.begin(), names.begin() + 3),
              (std::vector<std::string>{"height", "range", "ndt"}));
    for (const std::string& name : names) {
        EXPECT_EQ(core::ToString(ParseMethod(name)), name);
        EXPECT_EQ(MethodOf(ParseMethod(name)).name(), name);
    }
}

TEST(DescriptorMethod, AnUnknownNameListsTheValidOnes) {
    for (const char* name : {"sift", "", "a-name-far-longer-than-thirty-one-characters"}) {
        const std::string message = ErrorOf([&] { ParseMethod(name); });
        EXPECT_NE(message.find("unknown method"), std::string::npos) << message;
        EXPECT_NE(message.find("height, range, ndt"), std::string::npos) << message;
    }
    EXPECT_NE(ErrorOf([] { MethodOf(core::Method("sift")); }).find("unknown method 'sift'"),
              std::string::npos);
}

TEST(DescriptorMethod, EachPaperDecidesWithItsOwnComparisonAndDefault) {
    EXPECT_EQ(DefaultThreshold(core::Method::kHeight), 0.005);
    EXPECT_EQ(DefaultThreshold(core::Method::kRange), 0.005);
    EXPECT_EQ(DefaultThreshold(core::Method::kNdt), 0.0737);
    EXPECT_TRUE(IsMatch(core::Method::kHeight, 0.005, 0.005));  // W <= tau (Röhling eq. 7)
    EXPECT_FALSE(IsMatch(core::Method::kNdt, 0.05, 0.05));      // sigma' < t_d (Magnusson)
    EXPECT_TRUE(IsMatch(core::Method::kNdt, 0.049, 0.05));
}

TEST(DescriptorMethod, AThresholdMustBeAbleToDecide) {
    EXPECT_NO_THROW(MethodOf(core::Method::kHeight).ValidateThreshold(1.0));
    const std::string message =
        ErrorOf([] { MethodOf(core::Method::kRange).ValidateThreshold(1.5); });
    EXPECT_NE(message.find("in [0, 1] for range (the range of W)"), std::string::npos) << message;
    EXPECT_NO_THROW(MethodOf(core::Method::kNdt).ValidateThreshold(1.5));  // sigma' is unbounded
    for (double bad : {-0.1, std::nan(""), HUGE_VAL}) {
        EXPECT_THROW(MethodOf(core::Method::kNdt).ValidateThreshold(bad), core::ConfigError);
    }
    DetectorConfig detection;
    detection.threshold = 1.5;
    core::DescriptorConfig height;
    height.method = core::Method::kHeight;
    EXPECT_THROW(LoopDetector(height, detection), core::ConfigError);
    EXPECT_THROW(
        DetectFromMatrix(SimilarityMatrix(2), {0.0, 1.0}, detection, core::Method::kHeight),
        core::ConfigError);
}

TEST(DescriptorMethod, ANameIsRegisteredOnce) {
    const std::string message =
        ErrorOf([] { RegisterMethod(std::make_shared<HistogramMethod>(core::Method::kRange)); });
    EXPECT_NE(message.find("'range' is already registered"), std::string::npos) << message;
    EXPECT_THROW(RegisterMethod(nullptr), core::ConfigError);
    EXPECT_THROW(HistogramMethod{core::Method::kNdt}, core::ConfigError);
}

TEST(DescriptorMethod, DescriptorsOfTwoMethodsAreNotCompared) {
    core::DescriptorConfig height;
    height.method = core::Method::kHeight;
    core::DescriptorConfig range;
    range.method = core::Method::kRange;
    const core::PointCloud cloud = test::RandomCloud(500, 1);
    const core::Descriptor a = ComputeDescriptor(cloud, height);
    const core::Descriptor b = ComputeDescriptor(cloud, range);
    EXPECT_EQ(DescriptorDistance(a, a), 0.0);
    EXPECT_NE(ErrorOf([&] { DescriptorDistance(a, b); }).find("cannot compare a height"),
              std::string::npos);
    EXPECT_THROW(a.ndt(), core::ConfigError);  // holds a histogram
}

// A ground plane and a wall, dense enough for NDT cells, with random points between them.
core::PointCloud GroundAndWall() {
    core::PointCloud cloud = test::RandomCloud(2000, 3);
    for (int i = 0; i < 150; ++i) {
        for (int j = 0; j < 150; ++j) {
            const float u = -7.5f + 0.1f * static_cast<float>(i);
            const float v = -7.5f + 0.1f * static_cast<float>(j);
            cloud.emplace_back(u, v, -1.7f);
            cloud.emplace_back(8.0f, u, 0.05f * static_cast<float>(j) - 1.7f);
        }
    }
    return cloud;
}

TEST(DescriptorMethod, AViewOfPointsIsDescribedAsTheirCopy) {
    const core::PointCloud cloud = GroundAndWall();
    // A part of the cloud, so that a view reading past its end would differ.
    const core::PointsView part(cloud.data() + 1000, cloud.size() - 2000);
    const core::PointCloud copy(part.begin(), part.end());
    for (const core::Method& method :
         {core::Method::kHeight, core::Method::kRange, core::Method::kNdt}) {
        core::DescriptorConfig config;
        config.method = method;
        const core::Descriptor viewed = ComputeDescriptorView(part, config);
        const core::Descriptor copied = ComputeDescriptor(copy, config);
        EXPECT_EQ(DescriptorDistance(viewed, copied), 0.0) << core::ToString(method);
        if (core::IsHistogramMethod(method)) {
            EXPECT_EQ(viewed.histogram().mass, copied.histogram().mass);
            EXPECT_EQ(viewed.histogram().points_used, copy.size());
        } else {
            EXPECT_EQ(viewed.ndt().cell_stats.points_used, copied.ndt().cell_stats.points_used);
        }
    }
}

TEST(DescriptorDatabase, TypedViewsBelongToTheirMethodAndCopiesAreDeep) {
    core::DescriptorConfig config;
    DescriptorDatabase histograms(config);
    histograms.Add(ComputeDescriptor(test::RandomCloud(500, 1), config), 0.0);
    ASSERT_NE(HistogramRows(histograms), nullptr);
    EXPECT_EQ(NdtSets(histograms), nullptr);
    DescriptorDatabase copy = histograms;
    copy.Add(ComputeDescriptor(test::RandomCloud(500, 2), config), 1.0);
    EXPECT_EQ(HistogramRows(histograms)->size(), 1U);
    EXPECT_EQ(HistogramRows(copy)->size(), 2U);
    config.method = core::Method::kNdt;
    const DescriptorDatabase ndt(config);
    EXPECT_EQ(HistogramRows(ndt), nullptr);
    ASSERT_NE(NdtSets(ndt), nullptr);
}

// An NDT descriptor of another shape (range intervals x features) is refused where it is added,
// as a histogram of other bins is, not left to fail every later distance.
TEST(DescriptorDatabase, AnNdtDescriptorOfAnotherShapeIsRefusedWhenAdded) {
    core::DescriptorConfig config;
    config.method = core::Method::kNdt;
    DescriptorDatabase database(config);
    const core::PointCloud cloud = GroundAndWall();
    database.Add(ComputeDescriptor(cloud, config), 0.0);
    core::DescriptorConfig other = config;
    other.ndt.planar_classes += 1;
    EXPECT_THROW(database.Add(ComputeDescriptor(cloud, other), 1.0), core::ConfigError);
    database.Add(ComputeDescriptor(cloud, config), 2.0);
    EXPECT_EQ(database.size(), 2U);
    EXPECT_EQ(database.Distance(0, 1), 0.0);
}

}  // namespace
}  // namespace lidarloop::pipeline
