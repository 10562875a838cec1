#include <gtest/gtest.h>

#include "lidarloop/core/descriptor_config.hpp"
#include "lidarloop/core/error.hpp"

#include <limits>
#include <optional>
#include <string>
#include <vector>

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

std::string ConfigErrorOf(const auto& config) {
    try {
        config.Validate();
    } catch (const ConfigError& e) {
        return e.what();
    }
    return "(valid)";
}

// The range checks come from the declarations (Declare), in one form for every section.
TEST(DescriptorConfig, HistogramAndNdtRangesComeFromTheirDeclarations) {
    HistogramConfig histogram;
    histogram.bins = 0;
    EXPECT_EQ(ConfigErrorOf(histogram), "histogram.bins must be in [1, 1000000], got 0");
    histogram = {};
    histogram.range_min_m = -1.0;
    EXPECT_EQ(ConfigErrorOf(histogram), "histogram.range_min_m must be >= 0, got -1");
    NdtConfig ndt;
    ndt.cell_size_m = 0.0;
    EXPECT_EQ(ConfigErrorOf(ndt), "ndt.cell_size_m must be in [0.01, 100], got 0");
    ndt = {};
    ndt.min_points_per_cell = 2;
    EXPECT_EQ(ConfigErrorOf(ndt), "ndt.min_points_per_cell must be in [3, 1000000], got 2");
    ndt = {};
    for (const double open_bound : {0.0, 1.0}) {
        ndt.eigen_ratio_threshold = open_bound;
        EXPECT_EQ(ConfigErrorOf(ndt), "ndt.eigen_ratio_threshold must be in (0, 1), got " +
                                          std::string(open_bound == 0.0 ? "0" : "1"));
    }
    ndt = {};
    ndt.ambiguity_ratio = 1.5;
    EXPECT_EQ(ConfigErrorOf(ndt), "ndt.ambiguity_ratio must be in [0, 1], got 1.5");
    // Not simple ranges: still Validate's own checks.
    histogram = {};
    histogram.height_min_m = std::numeric_limits<double>::quiet_NaN();
    EXPECT_EQ(ConfigErrorOf(histogram), "histogram.height_min_m must be a finite number");
    ndt = {};
    ndt.spherical_classes = ndt.planar_classes = ndt.linear_classes = 0;
    EXPECT_NE(ConfigErrorOf(ndt).find("at least one of spherical"), std::string::npos);
}

// The keys in YAML order, enums visited by name: what flags, keywords and tables are made of.
class Keys final : public ParameterVisitor {
public:
    void Visit(const ParameterInfo& i, bool&) override { Add(i, "bool"); }
    void Visit(const ParameterInfo& i, int&) override { Add(i, "int"); }
    void Visit(const ParameterInfo& i, std::size_t&) override { Add(i, "size"); }
    void Visit(const ParameterInfo& i, double&) override { Add(i, "double"); }
    void Visit(const ParameterInfo& i, std::optional<double>&) override { Add(i, "optional"); }
    void Visit(const ParameterInfo& i, std::vector<double>&) override { Add(i, "list"); }
    void Visit(const ParameterInfo& i, std::string& value) override { Add(i, "name " + value); }
    std::vector<std::string> keys;

private:
    void Add(const ParameterInfo& info, const std::string& type) {
        keys.push_back(std::string(info.key) + ": " + type);
    }
};

TEST(DescriptorConfig, HistogramAndNdtDeclareEveryParameterInOrder) {
    Keys histogram;
    VisitCopies(HistogramConfig{}, histogram);
    EXPECT_EQ(histogram.keys,
              (std::vector<std::string>{"bins: int", "up_vector: name fixed",
                                        "sensor_height_m: double", "height_min_m: double",
                                        "height_max_m: double", "range_min_m: double",
                                        "range_max_m: double", "out_of_range: name clamp"}));
    Keys ndt;
    VisitCopies(NdtConfig{}, ndt);
    EXPECT_EQ(ndt.keys, (std::vector<std::string>{
                            "cell_size_m: double", "min_points_per_cell: int",
                            "eigen_ratio_threshold: double", "spherical_classes: int",
                            "planar_classes: int", "linear_classes: int", "range_limits_m: list",
                            "normalise_rotation: bool", "ambiguity_ratio: double",
                            "align_to_mean_direction: bool", "regrid_rotations: bool"}));
}

TEST(Parameters, RangeTextForMessagesAndHelp) {
    const ParameterInfo closed{"k", "", "", 1, 200};
    EXPECT_EQ(RangeText<int>(closed), "[1, 200]");
    EXPECT_EQ(RangeText<int>(closed, " to "), "1 to 200");
    const ParameterInfo open{"k", "", "", 0.0, 1.0, true};
    EXPECT_EQ(RangeText<double>(open), "(0, 1)");
    EXPECT_EQ(RangeText<double>(open, " to "), "0 to 1, exclusive");
    EXPECT_EQ(RangeText<double>({"k", "", "", 0.01}), ">= 0.01");
    EXPECT_EQ(RangeText<double>({"k", "", "", -std::numeric_limits<double>::infinity(), 5.0}),
              "<= 5");
    EXPECT_EQ(RangeText<double>({"k", "", ""}), "");
}

TEST(DescriptorConfig, OutOfRangePolicyNamesRoundTrip) {
    EXPECT_EQ(ParseOutOfRangePolicy("clamp"), OutOfRangePolicy::kClamp);
    EXPECT_EQ(ParseOutOfRangePolicy("drop"), OutOfRangePolicy::kDrop);
    EXPECT_EQ(ToString(OutOfRangePolicy::kDrop), "drop");
    EXPECT_THROW(ParseOutOfRangePolicy("wrap"), ConfigError);
}

}  // namespace
}  // namespace lidarloop::core
