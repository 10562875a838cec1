#include <gtest/gtest.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/pipeline/candidate_verification.hpp"
#include "lidarloop/pipeline/loop_detector.hpp"
#include "lidarloop/pipeline/sequence.hpp"
#include "registration/registration_test_utils.hpp"

namespace lidarloop::pipeline {
namespace {

// Three distinct places, then place 0 revisited 1.5 m to the side and turned by 170 degrees,
// and place 1 seen again from 2 m further on: scans 3 and 4 have a true loop among the scans at
// least two back.
struct Sequence {
    std::vector<core::PointCloud> scans;
    core::Transform T_0_3;  // true T_match_query of the revisit 3 -> 0
};

Sequence MakeSequence() {
    Sequence s;
    for (std::uint64_t seed : {1, 2, 3}) s.scans.push_back(test::SyntheticPlace(seed));
    const core::Transform T_3_0 = test::PlanarTransform(1.0, -1.5, 170.0);
    s.scans.push_back(test::Transformed(s.scans[0], T_3_0));
    s.scans.push_back(test::Transformed(s.scans[1], test::PlanarTransform(-2.0, 0.0, 0.0)));
    s.T_0_3 = T_3_0.inverse();
    return s;
}

DetectorConfig Verifying() {
    DetectorConfig detector;
    detector.min_gap = {2.0, core::MinGap::Unit::kScans};
    detector.top_k = 3;
    return detector;
}

TEST(OnlineVerification, EqualsVerifyingTheOfflineCandidates) {
    const Sequence sequence = MakeSequence();
    const DetectorConfig detector = Verifying();
    core::DescriptorConfig config;
    config.method = core::Method::kRange;
    LoopDetector online(config, detector);
    std::vector<LoopQuery> online_results;
    std::vector<double> times;
    std::vector<registration::CompactPreparedScan> prepared;
    for (std::size_t i = 0; i < sequence.scans.size(); ++i) {
        times.push_back(static_cast<double>(i));
        online_results.push_back(online.Process(sequence.scans[i], times.back()));
        prepared.emplace_back(
            registration::PrepareScan(sequence.scans[i], detector.verification.reduction));
    }
    std::vector<LoopQuery> offline = DetectFromMatrix(ComputeSimilarityMatrix(online.database()),
                                                      times, detector, core::Method::kRange);
    VerifyQueries(offline, prepared, detector, core::Method::kRange, Execution::kSerial);
    for (std::size_t i = 0; i < offline.size(); ++i) {
        ASSERT_EQ(online_results[i].verifications.size(), offline[i].verifications.size()) << i;
        for (std::size_t c = 0; c < offline[i].verifications.size(); ++c) {
            const auto& a = online_results[i].verifications[c];
            const auto& b = offline[i].verifications[c];
            EXPECT_EQ(a.accepted, b.accepted) << i << " " << c;
            EXPECT_EQ(a.reason, b.reason) << i << " " << c;
            EXPECT_TRUE(a.T_match_query.isApprox(b.T_match_query, 1e-9)) << i << " " << c;
        }
        EXPECT_EQ(online_results[i].accepted, offline[i].accepted) << i;
    }
    // The revisit of place 0 is the loop of scan 3, at the true pose.
    const LoopQuery& revisit = online_results[3];
    ASSERT_TRUE(revisit.loop().has_value());
    EXPECT_EQ(revisit.candidates[*revisit.loop()].index, 0U);
    const core::Transform error =
        sequence.T_0_3.inverse() * revisit.verifications[*revisit.loop()].T_match_query;
    EXPECT_LT(error.translation().norm(), 0.1);
    EXPECT_LT(Eigen::AngleAxisd(error.linear()).angle(), 0.5 * M_PI / 180.0);
    // Scan 2 has only scan 0 as a candidate, another place: no loop.
    EXPECT_FALSE(online_results[2].accepted);
}

TEST(OnlineVerification, KeepsReducedScansAndCountsTheirBytes) {
    const Sequence sequence = MakeSequence();
    core::DescriptorConfig config;
    config.method = core::Method::kRange;
    LoopDetector online(config, Verifying());
    std::size_t raw_bytes = 0;
    for (std::size_t i = 0; i < sequence.scans.size(); ++i) {
        online.Process(sequence.scans[i], static_cast<double>(i));
        raw_bytes += sequence.scans[i].size() * sizeof(Eigen::Vector3f);
    }
    std::size_t sum = 0;
    ASSERT_EQ(online.prepared_scans().size(), sequence.scans.size());
    for (const auto& scan : online.prepared_scans()) {
        ASSERT_TRUE(scan.prepared());
        sum += scan.MemoryBytes();
    }
    EXPECT_EQ(online.prepared_bytes(), sum);
    EXPECT_GT(sum, 0U);
    EXPECT_LT(sum, raw_bytes);
}

TEST(OnlineVerification, ScansGivenAsDescriptorsAreNotVerified) {
    const Sequence sequence = MakeSequence();
    core::DescriptorConfig config;
    config.method = core::Method::kRange;
    LoopDetector online(config, Verifying());
    // The first three as descriptors only: the revisit's candidates cannot be registered.
    for (std::size_t i = 0; i < 3; ++i) {
        online.Process(ComputeDescriptor(sequence.scans[i], config), static_cast<double>(i));
    }
    const LoopQuery revisit = online.Process(sequence.scans[3], 3.0);
    ASSERT_TRUE(revisit.verified());
    for (const auto& v : revisit.verifications) {
        EXPECT_FALSE(v.accepted);
        EXPECT_EQ(v.reason, registration::RejectReason::kTooFewPoints);
    }
    EXPECT_FALSE(revisit.accepted);
    // A descriptor-only query is decided by the threshold alone (not verified).
    const LoopQuery unverified = online.Process(ComputeDescriptor(sequence.scans[4], config), 4.0);
    EXPECT_FALSE(unverified.verified());
}

TEST(OnlineVerification, PreparedScansMustMatchTheDatabase) {
    core::DescriptorConfig config;
    DescriptorDatabase database(config);
    database.Add(ComputeDescriptor(test::SyntheticPlace(1), config), 0.0);
    std::vector<registration::PreparedScan> two(2);
    EXPECT_THROW(LoopDetector(database, Verifying(), two), core::ConfigError);
}

}  // namespace
}  // namespace lidarloop::pipeline
