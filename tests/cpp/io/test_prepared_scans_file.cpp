// database.scans: a round trip keeps every point, normal, flag and figure; damaged files are read
// errors naming the file, never a crash.
#include <sys/resource.h>

#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "lidarloop/io/prepared_scans_file.hpp"
#include "lidarloop/io/read_error.hpp"
#include "registration/registration_test_utils.hpp"
#include "test_utils.hpp"

namespace lidarloop::io {
namespace {

std::vector<registration::PreparedScan> TwoScansAndAGap() {
    const registration::ScanReductionConfig reduction;
    return {registration::PrepareScan(test::SyntheticPlace(1), reduction),
            {},
            registration::PrepareScan(test::SyntheticPlace(2), reduction)};
}

TEST(PreparedScansFile, RoundTripKeepsEverything) {
    const test::TempDir dir;
    const auto scans = TwoScansAndAGap();
    registration::ScanReductionConfig reduction;
    reduction.voxel_m = 0.4;
    SavePreparedScans(dir / "m.scans", scans, reduction);
    const StoredPreparedScans loaded = LoadPreparedScans(dir / "m.scans");
    EXPECT_EQ(loaded.reduction, reduction);
    ASSERT_EQ(loaded.scans.size(), 3U);
    EXPECT_FALSE(loaded.scans[1].structure);
    for (const std::size_t i : {0, 2}) {
        const auto& a = scans[i];
        const auto& b = loaded.scans[i];
        ASSERT_TRUE(b.structure && b.ground);
        EXPECT_EQ(a.structure->points(), b.structure->points());
        EXPECT_EQ(a.structure->normals(), b.structure->normals());
        EXPECT_EQ(a.ground->points(), b.ground->points());
        EXPECT_EQ(a.structure_distinctive, b.structure_distinctive);
        EXPECT_EQ(a.structure_roughness_m, b.structure_roughness_m);
        EXPECT_EQ(a.input_points, b.input_points);
    }
    EXPECT_EQ(PreparedScansPathOf(dir / "database.lldb"), dir / "database.scans");
}

long PeakResidentKiB() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return usage.ru_maxrss;
}

// Issue 25 (12): saving once encoded the whole file in memory, so the end of a long detect run
// peaked at its prepared scans plus the size of database.scans. 2,000 entries that share one
// scan make a ~100 MB file from almost no memory; saving it must not raise the peak by that.
TEST(PreparedScansFile, SavingHoldsNoCopyOfTheFile) {
    const std::vector<registration::PreparedScan> one = TwoScansAndAGap();
    const std::vector<registration::PreparedScan> scans(2000, one.front());
    const auto scan_bytes = static_cast<long>(24 * one.front().structure->size());
    const long file_kib = 2000 * scan_bytes / 1024;
    ASSERT_GT(file_kib, 40 * 1024) << "too small a file to tell";
    const long before_kib = PeakResidentKiB();
    SavePreparedScans("/dev/null", scans, {});
    EXPECT_LT(PeakResidentKiB() - before_kib, file_kib / 4) << "file " << file_kib << " KiB";
}

// Written as it goes: a failed write must still be an error, not a file that looks whole.
TEST(PreparedScansFile, AFullDiskIsAnError) {
    if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
    EXPECT_THROW(SavePreparedScans("/dev/full", TwoScansAndAGap(), {}), WriteError);
}

TEST(PreparedScansFile, DamagedFilesAreReadErrors) {
    const test::TempDir dir;
    SavePreparedScans(dir / "m.scans", TwoScansAndAGap(), {});
    const std::string bytes = test::ReadFile(dir / "m.scans");
    const auto error_of = [&](const std::string& content) {
        test::WriteFile(dir / "bad.scans", content);
        try {
            LoadPreparedScans(dir / "bad.scans");
        } catch (const ReadError& e) {
            return std::string(e.what());
        }
        return std::string("no ReadError");
    };
    EXPECT_NE(error_of("").find("bad.scans"), std::string::npos);
    EXPECT_NE(error_of("LLDB0001" + bytes.substr(8)).find("wrong magic"), std::string::npos);
    // A file of the previous format holds a roughness the acceptance rule no longer reads.
    EXPECT_NE(error_of("LLPS0001" + bytes.substr(8)).find("run detect again"), std::string::npos);
    EXPECT_NE(error_of(bytes.substr(0, bytes.size() / 2)).find("truncated"), std::string::npos);
    EXPECT_NE(error_of(bytes + "x").find("trailing"), std::string::npos);
    // The last float of the file is a ground normal's z: make it NaN.
    std::string nan_bytes = bytes;
    const float nan = std::nanf("");
    nan_bytes.replace(nan_bytes.size() - sizeof(float), sizeof(float),
                      reinterpret_cast<const char*>(&nan), sizeof(float));
    EXPECT_NE(error_of(nan_bytes).find("non-finite"), std::string::npos);
    EXPECT_THROW(LoadPreparedScans(dir / "missing.scans"), ReadError);
}

}  // namespace
}  // namespace lidarloop::io
