#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "io/io_test_utils.hpp"
#include "lidarloop/core/descriptor.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/io/database_file.hpp"
#include "lidarloop/io/plot.hpp"
#include "lidarloop/io/png.hpp"
#include "lidarloop/io/results_csv.hpp"
#include "lidarloop/io/similarity_file.hpp"
#include "lidarloop/io/similarity_image.hpp"
#include "lidarloop/pipeline/loop_detector.hpp"
#include "lidarloop/pipeline/ndt_method.hpp"
#include "lidarloop/pipeline/scancontext_method.hpp"
#include "test_utils.hpp"

namespace lidarloop::io {
namespace {

pipeline::DescriptorDatabase SmallDatabase(core::Method method) {
    core::DescriptorConfig config;
    config.method = method;
    config.histogram.bins = 24;
    pipeline::DescriptorDatabase database(config);
    for (unsigned i = 0; i < 6; ++i) {
        database.Add(pipeline::ComputeDescriptor(test::RandomCloud(3000, i, 5.0f), config),
                     0.5 * i);
    }
    database.AddMissing(3.0);
    return database;
}

TEST(SimilarityFile, RoundTripsExactly) {
    test::TempDir dir;
    const auto database = SmallDatabase(core::Method::kRange);
    const auto matrix = pipeline::ComputeSimilarityMatrix(database);
    WriteSimilarityMatrix(dir / "s.bin", matrix, core::Method::kRange);
    const StoredSimilarity stored = ReadSimilarityMatrix(dir / "s.bin");
    EXPECT_EQ(stored.method, core::Method::kRange);
    EXPECT_EQ(stored.matrix.size(), 7U);
    EXPECT_EQ(stored.matrix.condensed(), matrix.condensed());
    EXPECT_EQ(test::ReadFile(dir / "s.bin").size(), 8 + 8 + 5 + 8 + 21 * 4U);
}

TEST(SimilarityFile, BadFilesAreClearErrors) {
    test::TempDir dir;
    WriteSimilarityMatrix(dir / "s.bin", pipeline::SimilarityMatrix(40), core::Method::kHeight);
    const std::string good = test::ReadFile(dir / "s.bin");
    test::WriteFile(dir / "cut.bin", good.substr(0, good.size() - 3));
    test::ExpectReadError(ReadSimilarityMatrix, dir / "cut.bin", "truncated: distances");
    test::WriteFile(dir / "long.bin", good + "x");
    test::ExpectReadError(ReadSimilarityMatrix, dir / "long.bin", "trailing bytes");
    test::WriteFile(dir / "magic.bin", "PK\x03\x04" + good);
    test::ExpectReadError(ReadSimilarityMatrix, dir / "magic.bin", "wrong magic");
    std::string method = good;
    method.replace(16, 6, "heigth");
    test::WriteFile(dir / "method.bin", method);
    test::ExpectReadError(ReadSimilarityMatrix, dir / "method.bin", "unknown method 'heigth'");
    std::string huge = good;
    huge.replace(22, 8, std::string("\0\0\0\0\0\x01\0\0", 8));  // 2^40 scans
    test::WriteFile(dir / "huge.bin", huge);
    test::ExpectReadError(ReadSimilarityMatrix, dir / "huge.bin", "absurd scan count");
    test::ExpectReadError(ReadSimilarityMatrix, dir / "missing.bin", "no such file");
}

void ExpectSameDatabase(const pipeline::DescriptorDatabase& a,
                        const pipeline::DescriptorDatabase& b) {
    ASSERT_EQ(a.size(), b.size());
    EXPECT_EQ(a.method(), b.method());
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a.IsValid(i), b.IsValid(i));
        EXPECT_EQ(a.TimeS(i), b.TimeS(i));
        for (std::size_t j = 0; j < a.size(); ++j) EXPECT_EQ(a.Distance(i, j), b.Distance(i, j));
    }
}

TEST(DatabaseFile, RoundTripsHistogramAndNdtDatabases) {
    test::TempDir dir;
    for (core::Method method : {core::Method::kHeight, core::Method::kNdt}) {
        const auto database = SmallDatabase(method);
        SaveDatabase(dir / "db.bin", database);
        const auto loaded = LoadDatabase(dir / "db.bin");
        ExpectSameDatabase(database, loaded);
        EXPECT_EQ(loaded.config().histogram.bins, 24);
        // A detector continued from the loaded map finds the stored scans again.
        pipeline::DetectorConfig accept_all;
        accept_all.threshold = 1.0;
        pipeline::LoopDetector detector(loaded, accept_all);
        const auto query = detector.Query(
            pipeline::ComputeDescriptor(test::RandomCloud(3000, 2, 5.0f), loaded.config()));
        ASSERT_TRUE(query.has_match());
        EXPECT_EQ(query.candidates.front().index, 2U);
        EXPECT_EQ(query.candidates.front().distance, 0.0);
    }
}

TEST(DatabaseFile, BadFilesAreClearErrors) {
    test::TempDir dir;
    SaveDatabase(dir / "db.bin", SmallDatabase(core::Method::kNdt));
    const std::string good = test::ReadFile(dir / "db.bin");
    test::WriteFile(dir / "cut.bin", good.substr(0, good.size() / 2));
    test::ExpectReadError(LoadDatabase, dir / "cut.bin", "truncated");
    // Cut inside the configuration: the file named once.
    const std::filesystem::path short_file = dir / "short.bin";
    test::WriteFile(short_file, good.substr(0, 20));
    const std::string named = short_file.string() + ": ";
    try {
        LoadDatabase(short_file);
        ADD_FAILURE() << "no ReadError";
    } catch (const ReadError& error) {
        const std::string message = error.what();
        EXPECT_EQ(message.rfind(named + "truncated: configuration needs", 0), 0u) << message;
    }
    test::WriteFile(dir / "magic.bin", "LLSIM001" + good.substr(8));
    test::ExpectReadError(LoadDatabase, dir / "magic.bin", "not a lidarloop database");
    std::string config = good;
    const auto at = config.find("bins: 24");
    ASSERT_NE(at, std::string::npos);
    config.replace(at, 8, "binz: 24");
    test::WriteFile(dir / "config.bin", config);
    test::ExpectReadError(LoadDatabase, dir / "config.bin", "key 'histogram.binz': unknown key");
    // An embedded config with a key that is no name (found by fuzzing).
    std::string keyed = good;
    const auto key_at = keyed.find("  bins: 24");
    ASSERT_NE(key_at, std::string::npos);
    keyed.replace(key_at, 10, "  {b: 1}: ");
    test::WriteFile(dir / "key.bin", keyed);
    test::ExpectReadError(LoadDatabase, dir / "key.bin", "is a map, not a name");
    test::WriteFile(dir / "long.bin", good + "\x01");
    test::ExpectReadError(LoadDatabase, dir / "long.bin", "trailing bytes");
}

// The bytes of the first NDT descriptor's header in a saved database: rows, cols and total, as
// SaveDatabase writes them (little-endian, like the machines lidarloop runs on).
std::string DescriptorHeaderBytes(const core::NdtDescriptor& f) {
    std::string bytes(16, '\0');
    const auto rows = static_cast<std::uint32_t>(f.rows);
    const auto cols = static_cast<std::uint32_t>(f.cols);
    std::memcpy(bytes.data(), &rows, 4);
    std::memcpy(bytes.data() + 4, &cols, 4);
    std::memcpy(bytes.data() + 8, &f.total, 8);
    return bytes;
}

// A 0.1 database embeds the decision threshold of its detection (0.004 here) in the section of
// its method; it loads, with that threshold as its detection.threshold.
TEST(DatabaseFile, KeepsTheDetectionConfigItWasSavedWith) {
    test::TempDir dir;
    pipeline::DetectorConfig detection;
    detection.threshold = 0.01;
    detection.top_k = 3;
    SaveDatabase(dir / "db.bin", SmallDatabase(core::Method::kRange), detection);
    EXPECT_EQ(LoadStoredDatabase(dir / "db.bin").detection, detection);
    SaveDatabase(dir / "db.bin", SmallDatabase(core::Method::kRange));
    EXPECT_FALSE(LoadStoredDatabase(dir / "db.bin").detection.threshold.has_value());
}

TEST(DatabaseFile, ADatabaseOfVersion01LoadsWithItsThreshold) {
    const auto stored = LoadStoredDatabase(std::filesystem::path(LIDARLOOP_TEST_DATA_DIR) /
                                           "legacy" / "database_v0.1.lldb");
    EXPECT_EQ(stored.detection.threshold, 0.004);
    const pipeline::DescriptorDatabase& database = stored.database;
    EXPECT_EQ(database.method(), core::Method::kRange);
    EXPECT_EQ(database.config().histogram.bins, 20);
    ASSERT_EQ(database.size(), 2U);
    EXPECT_TRUE(database.IsValid(0));
    EXPECT_EQ(database.Distance(0, 1), 0.0);  // two copies of one scan
}

// An NDT descriptor whose stored total disagrees with its counts, or with a negative count, is a
// damaged file, not a descriptor to compare (sigma would be silently wrong).
TEST(DatabaseFile, DamagedNdtCountsAreClearErrors) {
    test::TempDir dir;
    const auto database = SmallDatabase(core::Method::kNdt);
    SaveDatabase(dir / "db.bin", database);
    const std::string good = test::ReadFile(dir / "db.bin");
    const core::NdtDescriptor& first = pipeline::NdtSets(database)->at(0).descriptors[0];
    const std::string header = DescriptorHeaderBytes(first);
    const auto at = good.find(header);
    ASSERT_NE(at, std::string::npos);

    std::string total = good;
    const double wrong_total = first.total + 3.0;
    total.replace(at + 8, 8, std::string(reinterpret_cast<const char*>(&wrong_total), 8));
    test::WriteFile(dir / "total.bin", total);
    test::ExpectReadError(LoadDatabase, dir / "total.bin",
                          "NDT cell total differs from its counts");

    std::string negative = good;
    const float minus_one = -1.0f;
    negative.replace(at + 16, 4, std::string(reinterpret_cast<const char*>(&minus_one), 4));
    test::WriteFile(dir / "negative.bin", negative);
    test::ExpectReadError(LoadDatabase, dir / "negative.bin", "finite and non-negative");
}

// `bytes` with the raw bytes of `value` written at `at`.
template <typename T>
std::string Patched(std::string bytes, std::size_t at, T value) {
    bytes.replace(at, sizeof(T), std::string(reinterpret_cast<const char*>(&value), sizeof(T)));
    return bytes;
}

// Where scan 2 (time 1.0 s, valid) begins in a saved SmallDatabase: its time.
std::size_t ThirdScanAt(const std::string& file) {
    const std::string time_and_flag = Patched(std::string(9, '\x01'), 0, 1.0);
    const auto at = file.find(time_and_flag);
    EXPECT_NE(at, std::string::npos);
    return at;
}

// A stored descriptor no method could have written (NaN, a histogram that does not rise from 0
// to 1, a rotation that is none) is a damaged file: loaded, it crashed the neighbour index or
// gave other loops without a word.
TEST(DatabaseFile, ValuesNoDescriptorHasAreClearErrors) {
    test::TempDir dir;
    const auto check = [&](const std::string& bytes, const std::string& phrase) {
        test::WriteFile(dir / "bad.bin", bytes);
        test::ExpectReadError(LoadDatabase, dir / "bad.bin", phrase);
    };
    // 20 buckets: rows of 24 floats, the last 4 padding.
    core::DescriptorConfig config;
    config.method = core::Method::kRange;
    config.histogram.bins = 20;
    pipeline::DescriptorDatabase database(config);
    for (unsigned i = 0; i < 4; ++i)
        database.Add(pipeline::ComputeDescriptor(test::RandomCloud(3000, i, 5.0f), config),
                     0.5 * i);
    SaveDatabase(dir / "range.bin", database);
    const std::string range = test::ReadFile(dir / "range.bin");
    const std::size_t scan = ThirdScanAt(range);
    const std::size_t row = scan + 9;
    check(Patched(range, scan, std::nan("")), "scan time is not finite");
    check(Patched(range, scan + 8, std::uint8_t{7}), "valid flag is neither 0 nor 1");
    check(Patched(range, row + 4 * 5, std::nanf("")), "not a rising share in [0, 1] at bucket 5");
    check(Patched(range, row + 4 * 5, -0.5f), "not a rising share in [0, 1] at bucket 5");
    check(Patched(range, row + 4 * 5, 1e30f), "not a rising share in [0, 1] at bucket 5");
    std::string halved = range;
    for (std::size_t k = 0; k < 20; ++k) {
        float value = 0.0f;
        std::memcpy(&value, range.data() + row + 4 * k, 4);
        halved = Patched(halved, row + 4 * k, 0.5f * value);
    }
    check(halved, "does not end at 1");
    check(Patched(range, row + 4 * 21, 0.25f), "values beyond its buckets");  // padding

    SaveDatabase(dir / "sc.bin", SmallDatabase(pipeline::ScanContextMethod::kMethod));
    const std::string sc = test::ReadFile(dir / "sc.bin");
    check(Patched(sc, ThirdScanAt(sc) + 9, std::numeric_limits<float>::infinity()),
          "scan context bins are not all finite");

    const auto ndt_database = SmallDatabase(core::Method::kNdt);
    SaveDatabase(dir / "ndt.bin", ndt_database);
    const std::string ndt = test::ReadFile(dir / "ndt.bin");
    const core::NdtDescriptor& first = pipeline::NdtSets(ndt_database)->at(0).descriptors[0];
    const auto at = ndt.find(DescriptorHeaderBytes(first));
    ASSERT_NE(at, std::string::npos);
    const std::size_t rotation = at + 16 + 4 * first.counts.size();
    check(Patched(ndt, rotation, 2.0), "NDT rotation is not a rotation matrix");
    check(Patched(ndt, rotation + 8, std::nan("")), "NDT rotation is not a rotation matrix");
}

// NDT scans of two shapes (range intervals x features) in one file are a damaged file: it loaded,
// and every distance to the odd scans failed later.
TEST(DatabaseFile, NdtScansOfTwoShapesAreAClearError) {
    test::TempDir dir;
    const auto saved = [&](int planar_classes, const char* name) {
        core::DescriptorConfig config;
        config.method = core::Method::kNdt;
        config.ndt.planar_classes = planar_classes;
        pipeline::DescriptorDatabase database(config);
        for (unsigned i = 0; i < 4; ++i)
            database.Add(pipeline::ComputeDescriptor(test::RandomCloud(3000, i, 5.0f), config),
                         0.5 * i);
        SaveDatabase(dir / name, database);
        return test::ReadFile(dir / name);
    };
    const std::string nine = saved(9, "nine.bin");
    const std::string ten = saved(10, "ten.bin");
    EXPECT_EQ(LoadDatabase(dir / "nine.bin").size(), 4U);
    // The first two scans of one, the last two of the other.
    test::WriteFile(dir / "mixed.bin",
                    nine.substr(0, ThirdScanAt(nine)) + ten.substr(ThirdScanAt(ten)));
    test::ExpectReadError(LoadDatabase, dir / "mixed.bin", "beside ones of");
}

TEST(Png, WritesAValidFileWithTheRightSize) {
    test::TempDir dir;
    Image image{3, 2, 1, {0, 128, 255, 255, 128, 0}};
    WritePng(dir / "a.png", image);
    const std::string bytes = test::ReadFile(dir / "a.png");
    ASSERT_GT(bytes.size(), 33U);
    EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
    EXPECT_EQ(bytes.substr(12, 4), "IHDR");
    EXPECT_EQ(bytes.substr(16, 8), std::string("\0\0\0\x03\0\0\0\x02", 8));  // width, height
    Image rgb{2, 2, 3, std::vector<std::uint8_t>(12, 7)};
    EXPECT_NO_THROW(WritePng(dir / "rgb.png", rgb));
}

TEST(Png, BadImagesAndPathsAreErrors) {
    test::TempDir dir;
    EXPECT_THROW(WritePng(dir / "a.png", Image{3, 2, 1, {1, 2, 3}}), core::ConfigError);
    EXPECT_THROW(WritePng(dir / "a.png", Image{0, 0, 1, {}}), core::ConfigError);
    EXPECT_THROW(WritePng(dir / "a.png", Image{1, 1, 2, {1, 2}}), core::ConfigError);
    EXPECT_THROW(WritePng(dir / "no" / "such" / "a.png", Image{1, 1, 1, {0}}), WriteError);
}

// A matrix of n scans: pair (i, j) at distance 0.001 * (i + j), pair (1, 8) at 0, scan 5
// missing (+inf).
pipeline::SimilarityMatrix TestMatrix(std::size_t n) {
    pipeline::SimilarityMatrix matrix(n);
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t j = i + 1; j < n; ++j) {
            matrix.set(i, j,
                       i == 5 || j == 5 ? std::numeric_limits<float>::infinity()
                                        : 0.001f * static_cast<float>(i + j));
        }
    }
    if (n > 8) matrix.set(1, 8, 0.0f);
    return matrix;
}

TEST(SimilarityImage, OnePixelPerPairUpToTheLimit) {
    const pipeline::SimilarityMatrix matrix = TestMatrix(12);
    const Image image = ThresholdImage(matrix, core::Method::kHeight, 0.005);
    ASSERT_EQ(image.width, 12);
    ASSERT_EQ(image.height, 12);
    for (std::size_t i = 0; i < 12; ++i) {
        for (std::size_t j = 0; j < 12; ++j) {
            const bool match = matrix.at(i, j) <= 0.005f;
            EXPECT_EQ(image.pixels[i * 12 + j], match ? 0 : 255) << i << " " << j;
        }
    }
    const Image grey = DistanceImage(matrix);
    EXPECT_EQ(grey.pixels[1 * 12 + 8], 0);
    EXPECT_EQ(grey.pixels[5 * 12 + 2], 255);  // missing
}

TEST(SimilarityImage, ABigMatrixIsDrawnInBlocksKeepingEveryMatch) {
    const pipeline::SimilarityMatrix matrix = TestMatrix(12);
    // 12 scans in at most 5 pixels: 3 scans a pixel, 4 x 4 pixels.
    const Image image = ThresholdImage(matrix, core::Method::kHeight, 0.0, 5);
    ASSERT_EQ(image.width, 4);
    ASSERT_EQ(image.height, 4);
    for (std::size_t r = 0; r < 4; ++r) {
        for (std::size_t c = 0; c < 4; ++c) {
            // Only the diagonal (distance 0 to itself) and the block of pair (1, 8) match.
            const bool match = r == c || (r == 0 && c == 2) || (r == 2 && c == 0);
            EXPECT_EQ(image.pixels[r * 4 + c], match ? 0 : 255) << r << " " << c;
        }
    }
    const Image grey = DistanceImage(matrix, 5);
    EXPECT_EQ(grey.width, 4);
    EXPECT_EQ(grey.pixels[0 * 4 + 2], 0);
    EXPECT_GT(grey.pixels[3 * 4 + 1], 0);  // smallest of scans 9..11 x 3..5: 0.012, grey
}

TEST(ResultsCsv, ReadsColumnsByNameAndKeepsEmptyFields) {
    test::TempDir dir;
    test::WriteFile(
        dir / "loops.csv",
        "query,match,distance,second_ratio,accepted\n3,0,0.0042,,1\n\n7,2,1e-3,0.5,0\r\n");
    const auto results = ReadResultsCsv(dir / "loops.csv");
    ASSERT_EQ(results.size(), 2U);
    EXPECT_EQ(results[0].query, 3U);
    EXPECT_EQ(results[0].match, 0U);
    EXPECT_DOUBLE_EQ(results[0].distance, 0.0042);
    EXPECT_EQ(results[1].query, 7U);
    EXPECT_DOUBLE_EQ(results[1].distance, 0.001);
    test::WriteFile(dir / "reordered.csv", "distance, match, query\n0.5, 1, 9\n");
    const auto reordered = ReadResultsCsv(dir / "reordered.csv");
    ASSERT_EQ(reordered.size(), 1U);
    EXPECT_EQ(reordered[0].query, 9U);
    EXPECT_EQ(reordered[0].match, 1U);
}

TEST(ResultsCsv, BadFilesNameTheLine) {
    test::TempDir dir;
    const auto expect = [&](const std::string& text, const std::string& phrase) {
        test::WriteFile(dir / "r.csv", text);
        test::ExpectReadError(ReadResultsCsv, dir / "r.csv", phrase);
    };
    expect("", "empty file");
    expect("a,b,c\n1,2,3\n", "line 1: the header must name the columns query, match and distance");
    expect("query,match,distance\n1,2\n", "line 2: expected at least 3 columns, got 2");
    expect("query,match,distance\n-1,2,0.1\n", "line 2: query '-1' is not a scan number");
    expect("query,match,distance\n1,2.5,0.1\n", "line 2: match '2.5' is not a scan number");
    expect("query,match,distance\n1,2,nan\n", "line 2: distance 'nan' is not a number");
    expect("query,match,distance\n1,2,close\n", "line 2: distance 'close' is not a number");
    expect("query,match,distance\n1,2,0.1\n3,4,-inf\n", "line 3: distance '-inf' is -inf");
}

TEST(ResultsCsv, InfinityMeansRejected) {
    test::TempDir dir;
    test::WriteFile(dir / "r.csv", "query,match,distance\n3,0,inf\n");
    const auto results = ReadResultsCsv(dir / "r.csv");
    ASSERT_EQ(results.size(), 1U);
    EXPECT_EQ(results[0].distance, std::numeric_limits<double>::infinity());
}

TEST(Plot, ScriptHoldsDataTitlesAndQuotesEscaped) {
    Plot plot;
    plot.title = "ROC of Roehling's height";
    plot.x_label = "FPR";
    plot.y_label = "TPR";
    plot.series.push_back({"height", {0.0, 0.5, 1.0}, {0.0, 0.9, 1.0}, PlotSeries::Style::kLines});
    plot.vertical_lines = {0.25};
    const std::string script = GnuplotScript("out.png", plot);
    EXPECT_NE(script.find("'ROC of Roehling''s height'"), std::string::npos) << script;
    EXPECT_NE(script.find("$data0 << EOD\n0 0\n0.5 0.9\n1 1\nEOD"), std::string::npos);
    EXPECT_NE(script.find("set arrow from 0.25"), std::string::npos);
    EXPECT_NE(script.find("with lines lw 2 title 'height'"), std::string::npos);
}

// A results file that never detects anything leaves curves without points; gnuplot fails on
// an empty data block and on a plot with nothing to autoscale on.
TEST(Plot, SeriesWithoutPointsAreLeftOut) {
    Plot plot;
    plot.series.push_back({"empty", {}, {}, PlotSeries::Style::kSteps});
    plot.series.push_back({"one", {0.5}, {1.0}, PlotSeries::Style::kSteps});
    const std::string script = GnuplotScript("out.png", plot);
    EXPECT_NE(script.find("plot $data1 using 1:2"), std::string::npos) << script;
    EXPECT_EQ(script.find("title 'empty'"), std::string::npos) << script;
    plot.series.pop_back();
    const std::string empty = GnuplotScript("out.png", plot);
    EXPECT_NE(empty.find("set xrange [0:1]\nset yrange [0:1]\n"), std::string::npos) << empty;
    EXPECT_NE(empty.find("'no data'"), std::string::npos) << empty;
    EXPECT_NE(empty.find("plot NaN notitle"), std::string::npos) << empty;
}

TEST(Plot, RendersAPlotWithoutPoints) {
    if (!GnuplotAvailable()) GTEST_SKIP() << "gnuplot is not installed (scripts/setup installs it)";
    test::TempDir dir;
    Plot plot;
    plot.title = "nothing detected";
    plot.series.push_back({"a", {}, {}, PlotSeries::Style::kSteps});
    plot.series.push_back({"b", {}, {}, PlotSeries::Style::kLines});
    EXPECT_NO_THROW(RenderPlot(dir / "empty.png", plot));
    plot.series.clear();
    EXPECT_NO_THROW(RenderPlot(dir / "none.png", plot));
    EXPECT_EQ(test::ReadFile(dir / "none.png").substr(1, 3), "PNG");
}

TEST(Plot, RendersAPngWithGnuplot) {
    if (!GnuplotAvailable()) GTEST_SKIP() << "gnuplot is not installed (scripts/setup installs it)";
    test::TempDir dir;
    Plot plot;
    plot.title = "test";
    plot.series.push_back({"a", {1, 2, 3}, {3, 1, 2}, PlotSeries::Style::kPoints});
    RenderPlot(dir / "plot.png", plot);
    EXPECT_EQ(test::ReadFile(dir / "plot.png").substr(1, 3), "PNG");
    EXPECT_NE(test::ReadFile(dir / "plot.gp").find("$data0"), std::string::npos);
    EXPECT_THROW(RenderPlot(dir / "no" / "such" / "plot.png", plot), WriteError);
}

TEST(Plot, AFolderNameIsNeverShellText) {
    if (!GnuplotAvailable()) GTEST_SKIP() << "gnuplot is not installed (scripts/setup installs it)";
    test::TempDir dir;
    // Quotes, a semicolon and $(...): each would end or run shell text were the path in a command.
    const std::filesystem::path folder = dir / "it's; touch INJECTED; $(touch INJECTED2) '";
    std::filesystem::create_directories(folder);
    Plot plot;
    plot.title = "test";
    plot.series.push_back({"a", {1, 2, 3}, {3, 1, 2}, PlotSeries::Style::kLines});
    const std::filesystem::path here = std::filesystem::current_path();
    std::filesystem::current_path(dir.path());
    EXPECT_NO_THROW(RenderPlot(folder / "plot.png", plot));
    std::filesystem::current_path(here);
    EXPECT_FALSE(std::filesystem::exists(dir / "INJECTED"));
    EXPECT_FALSE(std::filesystem::exists(dir / "INJECTED2"));
    EXPECT_EQ(test::ReadFile(folder / "plot.png").substr(0, 4), "\x89PNG");
}

}  // namespace
}  // namespace lidarloop::io
