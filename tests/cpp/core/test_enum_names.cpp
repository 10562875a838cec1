#include "lidarloop/core/enum_names.hpp"

#include <array>
#include <string>
#include <string_view>

#include <gtest/gtest.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/histogram.hpp"
#include "lidarloop/core/min_gap.hpp"
#include "lidarloop/core/projection.hpp"
#include "test_utils.hpp"

namespace lidarloop::core {
namespace {

enum class Colour { kRed, kGreen, kBlue };

constexpr auto kColourNames = std::to_array<EnumName<Colour>>({
    {Colour::kRed, "red"},
    {Colour::kGreen, "green"},
    {Colour::kBlue, "blue"},
});

using test::ConfigErrorOf;

TEST(EnumNames, BothDirectionsComeFromOneTable) {
    static_assert(IsOneToOne(kColourNames));
    static_assert(NameOf(kColourNames, Colour::kGreen) == "green");
    static_assert(FindEnum(kColourNames, "blue") == Colour::kBlue);
    for (const auto& row : kColourNames) {
        EXPECT_EQ(ParseEnum(kColourNames, NameOf(kColourNames, row.value), "colour"), row.value);
    }
    EXPECT_EQ(FindEnum(kColourNames, "Red"), std::nullopt);  // names are case-sensitive
    EXPECT_EQ(FindEnum(kColourNames, ""), std::nullopt);
    EXPECT_EQ(NameOf(kColourNames, static_cast<Colour>(7)), "unknown");
    EXPECT_EQ(NameOf(kColourNames, static_cast<Colour>(7), "red"), "red");
}

TEST(EnumNames, TablesWithARepeatedValueOrNameAreNotOneToOne) {
    constexpr auto kAliases = std::to_array<EnumName<Colour>>({
        {Colour::kRed, "red"},
        {Colour::kRed, "rouge"},
    });
    constexpr auto kClash = std::to_array<EnumName<Colour>>({
        {Colour::kRed, "red"},
        {Colour::kBlue, "red"},
    });
    static_assert(!IsOneToOne(kAliases));
    static_assert(!IsOneToOne(kClash));
    // An alias table still parses every spelling.
    EXPECT_EQ(FindEnum(kAliases, "rouge"), Colour::kRed);
}

TEST(EnumNames, JoinNamesListsTheTableInOrder) {
    EXPECT_EQ(JoinNames(kColourNames), "red, green, blue");
    EXPECT_EQ(JoinNames(kColourNames, " or "), "red, green or blue");
    constexpr auto kOne = std::to_array<EnumName<Colour>>({{Colour::kRed, "red"}});
    EXPECT_EQ(JoinNames(kOne, " or "), "red");
}

TEST(EnumNames, ParseErrorNamesTheValueAndTheValidNames) {
    EXPECT_EQ(ConfigErrorOf([] { ParseEnum(kColourNames, "mauve", "colour"); }),
              "unknown colour 'mauve' (valid: red, green, blue)");
}

// The messages users see from the core enums, word for word.
TEST(EnumNames, CoreParseErrorsKeepTheirMessages) {
    EXPECT_EQ(ConfigErrorOf([] { ParseProjection("heigth"); }),
              "unknown projection 'heigth' (valid: height, range)");
    EXPECT_EQ(ConfigErrorOf([] { ParseUpVectorMode("sideways"); }),
              "unknown up vector mode 'sideways' (valid: fixed, pca)");
    EXPECT_EQ(ConfigErrorOf([] { ParseOutOfRangePolicy("wrap"); }),
              "unknown out-of-range policy 'wrap' (valid: clamp, drop)");
    EXPECT_EQ(ConfigErrorOf([] { ParseMinGapUnit("frames"); }),
              "unknown gap unit 'frames' (valid: scans, seconds, metres)");
}

TEST(EnumNames, CoreNamesRoundTrip) {
    EXPECT_EQ(ToString(Projection::kHeight), "height");
    EXPECT_EQ(ToString(Projection::kRange), "range");
    EXPECT_EQ(ToString(UpVectorMode::kFixed), "fixed");
    EXPECT_EQ(ToString(UpVectorMode::kPca), "pca");
    EXPECT_EQ(ToString(OutOfRangePolicy::kClamp), "clamp");
    EXPECT_EQ(ToString(OutOfRangePolicy::kDrop), "drop");
    EXPECT_EQ(ToString(MinGap::Unit::kScans), "scans");
    EXPECT_EQ(ToString(MinGap::Unit::kSeconds), "seconds");
    EXPECT_EQ(ToString(MinGap::Unit::kMetres), "metres");
    for (const auto unit : {MinGap::Unit::kScans, MinGap::Unit::kSeconds, MinGap::Unit::kMetres}) {
        EXPECT_EQ(ParseMinGapUnit(ToString(unit)), unit);
    }
}

}  // namespace
}  // namespace lidarloop::core
