#include <algorithm>
#include <limits>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include "lidarloop/core/angles.hpp"
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

// With every yaw searched, and with the yaws the layouts suggest (coarse.layout_yaw_window_deg).
class OnlineVerificationWindow : public ::testing::TestWithParam<double> {};

TEST_P(OnlineVerificationWindow, EqualsVerifyingTheOfflineCandidates) {
    const Sequence sequence = MakeSequence();
    DetectorConfig detector = Verifying();
    detector.verification.coarse.layout_yaw_window_deg = GetParam();
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
    // Offline as online: the shortlists in the order of the scans' layouts, their yaws searched.
    const LoopCheck layouts = LayoutOrderOf(prepared, detector.verification.coarse);
    EXPECT_EQ(static_cast<bool>(layouts.yaw_window), GetParam() < 180.0);
    std::vector<LoopQuery> offline =
        DetectFromMatrix(ComputeSimilarityMatrix(online.database()), times, detector,
                         core::Method::kRange, {}, layouts);
    VerifyQueries(offline, prepared, detector, core::Method::kRange, Execution::kSerial, {},
                  nullptr, layouts);
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
    // The window holds the loop's yaw (-170 degrees) and not a quarter turn from it.
    if (layouts.yaw_window) {
        const double deg = M_PI / 180.0;
        const registration::YawWindow window = layouts.YawWindow(3, 0);
        EXPECT_TRUE(window.Contains(-170.0 * deg));
        EXPECT_FALSE(window.Contains(-80.0 * deg));
    }
}

INSTANTIATE_TEST_SUITE_P(EveryYawAndTheLayouts, OnlineVerificationWindow,
                         ::testing::Values(180.0, 20.0));

// Online, each shortlist is ordered by the scans' layouts as offline detection orders it with the
// same layouts, and on these places that is not the descriptor's order.
TEST(OnlineVerification, OrdersTheShortlistByLayoutAsOffline) {
    DetectorConfig detector;
    detector.min_gap = {1.0, core::MinGap::Unit::kScans};
    detector.top_k = 3;
    detector.layout_shortlist = 8;
    core::DescriptorConfig config;
    config.method = core::Method::kRange;
    LoopDetector online(config, detector);
    std::vector<LoopQuery> results;
    std::vector<double> times;
    for (std::uint64_t seed = 1; seed <= 12; ++seed) {
        times.push_back(static_cast<double>(seed));
        results.push_back(online.Process(test::SyntheticPlace(seed), times.back()));
    }
    const SimilarityMatrix matrix = ComputeSimilarityMatrix(online.database());
    const std::vector<LoopQuery> offline =
        DetectFromMatrix(matrix, times, detector, core::Method::kRange, {},
                         LayoutOrderOf(online.prepared_scans(), {}));
    const std::vector<LoopQuery> ranked =
        DetectFromMatrix(matrix, times, detector, core::Method::kRange);
    const auto indices = [](const LoopQuery& q) {
        std::vector<std::size_t> result;
        for (const Neighbor& c : q.candidates) result.push_back(c.index);
        return result;
    };
    std::size_t reordered = 0;
    for (std::size_t i = 0; i < results.size(); ++i) {
        EXPECT_EQ(indices(results[i]), indices(offline[i])) << i;
        if (indices(ranked[i]) != indices(offline[i])) ++reordered;
    }
    EXPECT_GT(reordered, 2U);
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

// The sequence's odometry: places 0, 1 and 2 100 m apart, scans 3 and 4 where they truly are,
// and scan 3 put `error_m` further along x (drift, or the odometry of another place).
std::vector<core::Transform> Odometry(double error_m) {
    std::vector<core::Transform> T_odom_sensor;
    for (const double x_m : {0.0, 100.0, 200.0})
        T_odom_sensor.push_back(test::PlanarTransform(x_m, 0.0, 0.0));
    const core::Transform T_3_0 = test::PlanarTransform(1.0, -1.5, 170.0);
    T_odom_sensor.push_back(T_odom_sensor[0] * T_3_0.inverse());
    T_odom_sensor.back().translation().x() += error_m;
    T_odom_sensor.push_back(T_odom_sensor[1] * test::PlanarTransform(-2.0, 0.0, 0.0).inverse());
    return T_odom_sensor;
}

// What a gate was asked: the odometry's T_match_query and the path between, per call.
struct GateCall {
    core::Transform T_match_query_odometry;
    double path_m = 0.0;
};

// A gate that rejects a loop more than 5 m from the odometry's pose, and records each call.
OdometryGate FiveMetreGate(std::vector<GateCall>& calls) {
    return {
        [&calls](const core::Transform& T_loop, const core::Transform& T_odometry, double path_m) {
            calls.push_back({T_odometry, path_m});
            return (T_loop.inverse() * T_odometry).translation().norm() > 5.0;
        },
        {},
        {}};
}

// A detector whose degeneracy floor no registration passes on its own, but every one passes
// where the odometry judges the pose.
DetectorConfig OnlyTheOdometryPins() {
    DetectorConfig detector = Verifying();
    detector.verification.acceptance.min_constraining_points = 1'000'000;
    detector.verification.acceptance.min_constraining_points_with_odometry = 1;
    return detector;
}

std::vector<LoopQuery> ProcessWithOdometry(const std::vector<core::Transform>& odometry,
                                           std::vector<GateCall>& calls,
                                           const DetectorConfig& detector = Verifying(),
                                           bool with_gate = true) {
    const Sequence sequence = MakeSequence();
    core::DescriptorConfig config;
    config.method = core::Method::kRange;
    LoopDetector online(config, detector);
    if (with_gate) online.SetOdometryGate(FiveMetreGate(calls));
    std::vector<LoopQuery> results;
    for (std::size_t i = 0; i < sequence.scans.size(); ++i)
        results.push_back(online.Process(sequence.scans[i], static_cast<double>(i), odometry[i]));
    return results;
}

TEST(OnlineVerification, TheOdometryGateRejectsOnlyTheLoopsItContradicts) {
    std::vector<GateCall> calls;
    const std::vector<LoopQuery> agreeing = ProcessWithOdometry(Odometry(0.0), calls);
    ASSERT_TRUE(agreeing[3].loop() && agreeing[4].loop());
    EXPECT_EQ(agreeing[3].candidates[*agreeing[3].loop()].index, 0U);
    EXPECT_EQ(agreeing[4].candidates[*agreeing[4].loop()].index, 1U);
    // The gate was asked about each accepted loop with the odometry's pose and the path along it.
    ASSERT_FALSE(calls.empty());
    const auto odometry = Odometry(0.0);
    // Scans 0, 1, 2 are 100 m apart; scan 3 is where scan 2 leaves it.
    const double path_0_to_3_m =
        200.0 + (odometry[3].translation() - odometry[2].translation()).norm();
    const GateCall& first = calls.front();  // scan 3 to scan 0
    EXPECT_TRUE(first.T_match_query_odometry.isApprox(odometry[0].inverse() * odometry[3], 1e-12));
    EXPECT_NEAR(first.path_m, path_0_to_3_m, 1e-9);

    // 8 m off (within a loop's 10 m of scan 0, so still a candidate): the revisit of place 0
    // is registered and rejected, that of place 1 kept.
    calls.clear();
    const std::vector<LoopQuery> contradicted = ProcessWithOdometry(Odometry(8.0), calls);
    EXPECT_FALSE(contradicted[3].accepted);
    EXPECT_FALSE(contradicted[3].loop());
    const auto& verdicts = contradicted[3].verifications;
    ASSERT_EQ(verdicts.size(), contradicted[3].candidates.size());
    bool rejected_scan_0 = false;
    for (std::size_t c = 0; c < verdicts.size(); ++c) {
        rejected_scan_0 = rejected_scan_0 ||
                          (contradicted[3].candidates[c].index == 0 &&
                           verdicts[c].reason == registration::RejectReason::kOdometryMismatch &&
                           verdicts[c].registered_hypotheses > 0);
    }
    EXPECT_TRUE(rejected_scan_0);
    ASSERT_TRUE(contradicted[4].loop());
    EXPECT_EQ(contradicted[4].candidates[*contradicted[4].loop()].index, 1U);
}

// The odometry's degeneracy floor applies where the gate judges the pose, and only there.
TEST(OnlineVerification, TheOdometrysDegeneracyFloorNeedsTheGate) {
    std::vector<GateCall> calls;
    const DetectorConfig detector = OnlyTheOdometryPins();
    const std::vector<LoopQuery> gated = ProcessWithOdometry(Odometry(0.0), calls, detector);
    EXPECT_TRUE(gated[3].loop() && gated[4].loop());
    const std::vector<LoopQuery> alone =
        ProcessWithOdometry(Odometry(0.0), calls, detector, /*with_gate=*/false);
    for (const LoopQuery& query : alone) {
        EXPECT_FALSE(query.accepted) << query.query;
        for (const auto& verdict : query.verifications) {
            EXPECT_TRUE(verdict.reason != registration::RejectReason::kNone) << query.query;
        }
    }
    EXPECT_EQ(alone[3].verifications.front().reason, registration::RejectReason::kDegenerate);
}

TEST(OnlineVerification, TheOdometryIsGivenForEveryScanOrNone) {
    const Sequence sequence = MakeSequence();
    core::DescriptorConfig config;
    config.method = core::Method::kRange;
    const auto odometry = Odometry(0.0);
    LoopDetector with(config, Verifying());
    with.Process(sequence.scans[0], 0.0, odometry[0]);
    EXPECT_THROW(with.Process(sequence.scans[1], 1.0), core::ConfigError);
    LoopDetector without(config, Verifying());
    without.Process(sequence.scans[0], 0.0);
    EXPECT_THROW(without.Process(sequence.scans[1], 1.0, odometry[1]), core::ConfigError);
    core::Transform not_finite = odometry[1];
    not_finite.translation().x() = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(with.Process(sequence.scans[1], 1.0, not_finite), core::ConfigError);
    // The refused scans were not stored; the next good one is scan 1.
    EXPECT_EQ(with.database().size(), 1U);
    EXPECT_NO_THROW(with.Process(sequence.scans[1], 1.0, odometry[1]));
}

// Another place: the synthetic place mirrored along one axis (0: x, 1: y).
core::PointCloud Mirrored(core::PointCloud cloud, int axis) {
    for (Eigen::Vector3f& point : cloud) point[axis] = -point[axis];
    return cloud;
}

// A query of a place and four candidates in rank order: the place mirrored (rejected), the
// place seen from where the query is and from 1 m aside (both accepted), the place mirrored the
// other way (rejected).
struct RankedCandidates {
    LoopQuery query;
    registration::PreparedScan query_scan;
    std::vector<registration::PreparedScan> scans;  // by scan index; the query is scan 4
};

RankedCandidates MakeRankedCandidates(const DetectorConfig& detector) {
    const auto prepare = [&](const core::PointCloud& cloud) {
        return registration::PrepareScan(cloud, detector.verification.reduction);
    };
    RankedCandidates r;
    const core::PointCloud place = test::SyntheticPlace(1);
    r.scans = {prepare(Mirrored(place, 1)), prepare(place),
               prepare(test::Transformed(place, test::PlanarTransform(1.0, 0.5, 3.0))),
               prepare(Mirrored(place, 0))};
    r.query_scan = prepare(test::Transformed(place, test::PlanarTransform(0.5, -1.0, 170.0)));
    r.query.query = 4;
    for (std::size_t j = 0; j < r.scans.size(); ++j)
        r.query.candidates.push_back({j, 0.1 * static_cast<double>(j + 1)});
    return r;
}

LoopQuery Verified(RankedCandidates r, const DetectorConfig& detector, const LoopCheck& check = {},
                   const MoreLoopsWanted& more = {}) {
    VerifyQuery(
        r.query, r.query_scan, [&](std::size_t j) { return r.scans.at(j); }, detector,
        core::Method::kRange, nullptr, nullptr, Execution::kSerial, check, more);
    return r.query;
}

void ExpectSameVerdict(const registration::Verification& a, const registration::Verification& b,
                       std::size_t candidate) {
    EXPECT_EQ(a.accepted, b.accepted) << candidate;
    EXPECT_EQ(a.reason, b.reason) << candidate;
    EXPECT_TRUE(a.T_match_query.isApprox(b.T_match_query, 1e-12)) << candidate;
}

// One time per registered pair and one for the query's images, each on both clocks: what
// `lidarloop bench` sums into the online step. A pair's thread CPU time cannot exceed its wall
// time (0.05 ms: the clocks' resolution); pruned candidates are not timed.
TEST(VerifyQuery, TimesEachRegisteredPairOnBothClocks) {
    DetectorConfig detector = Verifying();
    detector.stop_at_first_loop = false;
    RankedCandidates ranked = MakeRankedCandidates(detector);
    detector.threshold = 0.25;  // prunes candidates 2 and 3 (distances 0.3 and 0.4)
    VerificationTimes times;
    VerifyQuery(
        ranked.query, ranked.query_scan, [&](std::size_t j) { return ranked.scans.at(j); },
        detector, core::Method::kRange, &times, nullptr, Execution::kSerial);
    ASSERT_EQ(times.pair_seconds.size(), 2U);
    ASSERT_EQ(times.pair_cpu_seconds.size(), 2U);
    ASSERT_EQ(times.query_seconds.size(), 1U);
    ASSERT_EQ(times.query_cpu_seconds.size(), 1U);
    for (std::size_t i = 0; i < 2; ++i) {
        EXPECT_GT(times.pair_cpu_seconds[i], 0.0) << i;
        EXPECT_LE(times.pair_cpu_seconds[i], times.pair_seconds[i] + 5e-5) << i;
    }
    EXPECT_GT(times.query_cpu_seconds[0], 0.0);
    EXPECT_LE(times.query_cpu_seconds[0], times.query_seconds[0] + 5e-5);
    VerificationTimes appended = times;
    appended.Append(times);
    EXPECT_EQ(appended.pair_cpu_seconds.size(), 4U);
    EXPECT_EQ(appended.query_cpu_seconds[1], times.query_cpu_seconds[0]);
}

// The check's yaw window reaches the coarse search: around the truth (the query is the place
// turned by 170 degrees) the verdicts are those of the full search; a quarter turn off, the
// true loops are not found.
TEST(VerifyQuery, TheChecksYawWindowLimitsTheCoarseSearch) {
    DetectorConfig detector = Verifying();
    detector.stop_at_first_loop = false;
    const RankedCandidates ranked = MakeRankedCandidates(detector);
    const LoopQuery full = Verified(ranked, detector);
    ASSERT_TRUE(full.verifications[1].accepted && full.verifications[2].accepted);
    const auto window_at = [](double centre_deg) {
        LoopCheck check;
        check.yaw_window = [centre_deg](std::size_t, std::size_t) {
            return registration::YawWindow{centre_deg * core::kRadiansPerDegree,
                                           10.0 * core::kRadiansPerDegree};
        };
        return check;
    };
    const LoopQuery around_truth = Verified(ranked, detector, window_at(-170.0));
    for (std::size_t c = 1; c <= 2; ++c)
        ExpectSameVerdict(around_truth.verifications[c], full.verifications[c], c);
    const LoopQuery quarter_off = Verified(ranked, detector, window_at(100.0));
    EXPECT_FALSE(quarter_off.verifications[1].accepted);
    EXPECT_FALSE(quarter_off.verifications[2].accepted);
}

// Candidates with windows apart (1 and 2 around the truth, 0 and 3 half a turn away): the
// query's images cover every candidate still to be registered, also the one a batch skipped
// before the check rejected the loop ahead of it, and each pair's verdict is that of a search
// of its own window alone.
TEST(VerifyQuery, EachCandidateIsSearchedInItsOwnYawWindow) {
    DetectorConfig detector = Verifying();
    const RankedCandidates ranked = MakeRankedCandidates(detector);
    LoopCheck check;
    check.yaw_window = [](std::size_t, std::size_t match) {
        const double centre_deg = match == 1 || match == 2 ? -170.0 : 10.0;
        return registration::YawWindow{centre_deg * core::kRadiansPerDegree,
                                       10.0 * core::kRadiansPerDegree};
    };
    check.reject = [](LoopQuery& query) {  // the first loop is one the odometry contradicts
        registration::Verification& v = query.verifications[1];
        if (v.accepted)
            v.accepted = false, v.reason = registration::RejectReason::kOdometryMismatch;
    };
    std::vector<registration::Verification> alone;
    for (std::size_t j = 0; j < ranked.scans.size(); ++j) {
        const registration::YawWindow window = check.YawWindow(ranked.query.query, j);
        const registration::CoarseQuery coarse(*ranked.query_scan.structure,
                                               detector.verification.coarse, {window});
        alone.push_back(registration::Verify(ranked.query_scan, coarse, ranked.scans[j],
                                             detector.verification, {}, window));
    }
    ASSERT_TRUE(alone[1].accepted && alone[2].accepted);
    for (const bool stop : {false, true}) {
        detector.stop_at_first_loop = stop;
        for (const int threads : {1, 2}) {
            LoopQuery query = ranked.query;
            tbb::task_arena(threads).execute([&] {
                VerifyQuery(
                    query, ranked.query_scan, [&](std::size_t j) { return ranked.scans.at(j); },
                    detector, core::Method::kRange, nullptr, nullptr,
                    threads > 1 ? Execution::kParallel : Execution::kSerial, check);
            });
            ASSERT_EQ(query.loop(), 2u) << stop << threads;
            EXPECT_EQ(query.verifications[1].reason, registration::RejectReason::kOdometryMismatch);
            for (const std::size_t c : {0u, 2u})
                ExpectSameVerdict(query.verifications[c], alone[c], c);
            if (!stop) ExpectSameVerdict(query.verifications[3], alone[3], 3);
        }
    }
}

// stop_at_first_loop registers in rank order up to the first accepted candidate, with the
// verdicts of registering every one, and leaves the rest kNotNeeded.
TEST(StopAtFirstLoop, RegistersInRankOrderUpToTheFirstAcceptedCandidate) {
    DetectorConfig detector = Verifying();
    EXPECT_TRUE(detector.stop_at_first_loop);  // the default
    detector.stop_at_first_loop = false;
    const RankedCandidates ranked = MakeRankedCandidates(detector);
    const LoopQuery every = Verified(ranked, detector);
    ASSERT_FALSE(every.verifications[0].accepted);
    ASSERT_TRUE(every.verifications[1].accepted && every.verifications[2].accepted);
    ASSERT_FALSE(every.verifications[3].accepted);

    detector.stop_at_first_loop = true;
    const LoopQuery first = Verified(ranked, detector);
    ASSERT_EQ(first.verifications.size(), 4u);
    for (const std::size_t c : {0u, 1u})
        ExpectSameVerdict(first.verifications[c], every.verifications[c], c);
    for (const std::size_t c : {2u, 3u})
        EXPECT_EQ(first.verifications[c].reason, registration::RejectReason::kNotNeeded) << c;
    ASSERT_TRUE(first.loop().has_value());
    EXPECT_EQ(*first.loop(), 1u);
    EXPECT_TRUE(first.accepted);
}

// A loop the check rejects (the odometry gate) lets the next candidate be registered.
TEST(StopAtFirstLoop, ALoopTheCheckRejectsLetsTheNextCandidateBeRegistered) {
    DetectorConfig detector = Verifying();
    detector.stop_at_first_loop = true;
    const RankedCandidates ranked = MakeRankedCandidates(detector);
    std::vector<std::size_t> checked_accepted;
    const LoopQuery first =
        Verified(ranked, detector,
                 LoopCheck{[&](LoopQuery& query) {
                               std::size_t accepted = 0;
                               for (registration::Verification& v : query.verifications) {
                                   if (!v.accepted) continue;
                                   ++accepted;
                                   if (&v == &query.verifications[1]) {
                                       v.accepted = false;
                                       v.reason = registration::RejectReason::kOdometryMismatch;
                                   }
                               }
                               checked_accepted.push_back(accepted);
                           },
                           {},
                           {},
                           {},
                           {},
                           {},
                           {},
                           {},
                           {}});
    EXPECT_EQ(checked_accepted, (std::vector<std::size_t>{1, 1}));  // one new loop a call
    EXPECT_EQ(first.verifications[1].reason, registration::RejectReason::kOdometryMismatch);
    EXPECT_TRUE(first.verifications[2].accepted);
    EXPECT_EQ(first.verifications[3].reason, registration::RejectReason::kNotNeeded);
    ASSERT_TRUE(first.loop().has_value());
    EXPECT_EQ(*first.loop(), 2u);

    // Without a loop among them every candidate is registered, as without the option.
    RankedCandidates elsewhere = ranked;
    elsewhere.query.candidates = {ranked.query.candidates[0], ranked.query.candidates[3]};
    const LoopQuery none = Verified(elsewhere, detector);
    detector.stop_at_first_loop = false;
    const LoopQuery all = Verified(elsewhere, detector);
    ASSERT_EQ(none.verifications.size(), 2u);
    for (const std::size_t c : {0u, 1u})
        ExpectSameVerdict(none.verifications[c], all.verifications[c], c);
    EXPECT_FALSE(none.accepted);
}

// After the first loop, the candidates the user still wants (the pose graph's loops far apart in
// path) are registered, with the verdicts of registering every one; the others are not.
TEST(StopAtFirstLoop, TheCandidatesStillWantedAfterTheLoopAreRegistered) {
    DetectorConfig detector = Verifying();
    detector.stop_at_first_loop = false;
    const RankedCandidates ranked = MakeRankedCandidates(detector);
    const LoopQuery every = Verified(ranked, detector);
    detector.stop_at_first_loop = true;
    std::vector<std::size_t> asked;
    const LoopQuery wanted = Verified(ranked, detector, {}, [&](const LoopQuery&, std::size_t c) {
        asked.push_back(c);
        return c == 3;
    });
    asked.erase(std::unique(asked.begin(), asked.end()), asked.end());
    EXPECT_EQ(asked, (std::vector<std::size_t>{2, 3}));  // only once the query has a loop
    for (const std::size_t c : {0u, 1u, 3u})
        ExpectSameVerdict(wanted.verifications[c], every.verifications[c], c);
    EXPECT_EQ(wanted.verifications[2].reason, registration::RejectReason::kNotNeeded);
    ASSERT_TRUE(wanted.loop().has_value());
    EXPECT_EQ(*wanted.loop(), 1u);
}

// Online, stopping at the first loop registers as many candidates at once as there are threads,
// then decides them in rank order: the verdicts of registering one after another, whatever the
// width, also when a cached loop inside a batch is rejected by the check and the candidate after
// it, skipped by the batch, must be registered after all.
TEST(StopAtFirstLoop, RegisteringSeveralAtOnceGivesTheVerdictsOfOneAfterAnother) {
    DetectorConfig detector = Verifying();
    const RankedCandidates ranked = MakeRankedCandidates(detector);
    const LoopCheck reject_candidate_1{
        [](LoopQuery& query) {
            registration::Verification& v = query.verifications[1];
            if (v.accepted)
                v.accepted = false, v.reason = registration::RejectReason::kOdometryMismatch;
        },
        {},
        {},
        {},
        {},
        {},
        {},
        {},
        {}};
    const auto verify = [&](int threads, Execution execution, const LoopCheck& check,
                            VerificationCache* cache) {
        LoopQuery query = ranked.query;
        tbb::task_arena(threads).execute([&] {
            VerifyQuery(
                query, ranked.query_scan, [&](std::size_t j) { return ranked.scans.at(j); },
                detector, core::Method::kRange, nullptr, cache, execution, check);
        });
        return query;
    };
    for (const LoopCheck& check : {LoopCheck{}, reject_candidate_1}) {
        const LoopQuery one_by_one = verify(1, Execution::kSerial, check, nullptr);
        for (const int threads : {2, 3, 4}) {
            VerificationCache cache;
            const LoopQuery batched = verify(threads, Execution::kParallel, check, &cache);
            const auto registered_1 = cache.Find(4, 1);  // before the check
            ASSERT_TRUE(registered_1 && registered_1->accepted) << threads;
            VerificationCache cached_loop;  // candidate 1's verdict known: the batch skips 2, 3
            cached_loop.Store(4, 1, *registered_1);
            const LoopQuery with_cached =
                verify(threads, Execution::kParallel, check, &cached_loop);
            for (std::size_t c = 0; c < 4; ++c) {
                ExpectSameVerdict(batched.verifications[c], one_by_one.verifications[c], c);
                ExpectSameVerdict(with_cached.verifications[c], one_by_one.verifications[c], c);
            }
        }
    }
}

// A candidate the odometry puts farther from the query than a loop's 10 m plus the gate allows
// cannot become a loop whatever its registration: it is not registered (reason odometry_mismatch,
// no hypothesis refined), and the other pairs keep their verdicts.
// 60 m off, the odometry puts scan 3 out of reach of a loop with scan 0: scan 0 is no
// candidate of scan 3, and scan 4's verdicts are unchanged.
TEST(OnlineVerification, AScanTheOdometryPutsOutOfReachIsNoCandidate) {
    std::vector<GateCall> calls;
    const std::vector<LoopQuery> near = ProcessWithOdometry(Odometry(0.0), calls);
    const std::vector<LoopQuery> far = ProcessWithOdometry(Odometry(60.0), calls);
    const auto has_candidate = [](const LoopQuery& query, std::size_t match) {
        return std::any_of(query.candidates.begin(), query.candidates.end(),
                           [match](const Neighbor& n) { return n.index == match; });
    };
    ASSERT_TRUE(has_candidate(near[3], 0));
    ASSERT_TRUE(near[3].loop());
    EXPECT_EQ(near[3].candidates[*near[3].loop()].index, 0U);
    EXPECT_FALSE(has_candidate(far[3], 0));
    EXPECT_FALSE(far[3].loop());
    ASSERT_EQ(near[4].verifications.size(), far[4].verifications.size());
    for (std::size_t c = 0; c < near[4].verifications.size(); ++c)
        ExpectSameVerdict(near[4].verifications[c], far[4].verifications[c], c);
}

// A candidate the check says cannot close (given to VerifyQuery all the same) is answered
// odometry_mismatch without a registration; the others are verified as without the check.
TEST(OnlineVerification, ACandidateTheCheckSaysCannotCloseIsNotRegistered) {
    DetectorConfig detector = Verifying();
    detector.stop_at_first_loop = false;
    const RankedCandidates ranked = MakeRankedCandidates(detector);
    LoopCheck rules_out_2;
    rules_out_2.may_close = [](std::size_t, std::size_t match, double) { return match != 2; };
    const LoopQuery checked = Verified(ranked, detector, rules_out_2);
    const LoopQuery unchecked = Verified(ranked, detector);
    ASSERT_TRUE(unchecked.verifications[2].accepted);
    EXPECT_EQ(checked.verifications[2].reason, registration::RejectReason::kOdometryMismatch);
    EXPECT_EQ(checked.verifications[2].registered_hypotheses, 0);
    for (const std::size_t c : {0U, 1U, 3U})
        ExpectSameVerdict(checked.verifications[c], unchecked.verifications[c], c);
}

TEST(OnlineVerification, PreparedScansMustMatchTheDatabase) {
    core::DescriptorConfig config;
    DescriptorDatabase database(config);
    database.Add(ComputeDescriptor(test::SyntheticPlace(1), config), 0.0);
    std::vector<registration::PreparedScan> two(2);
    EXPECT_THROW(LoopDetector(database, Verifying(), two), core::ConfigError);
}

// `check` gave candidate 2 of query 4 a looser degeneracy floor than `detector`'s (which no
// candidate passes): only it is accepted, with the verdict and pose of that floor alone (no other
// looser test), and the check was asked about every candidate.
void ExpectOnlyCandidate2HadTheLooserFloor(
    const RankedCandidates& ranked, const DetectorConfig& detector, const LoopCheck& check,
    std::vector<std::pair<std::size_t, std::size_t>>& asked) {
    const LoopQuery verified = Verified(ranked, detector, check);
    EXPECT_EQ(verified.verifications[1].reason, registration::RejectReason::kDegenerate);
    EXPECT_TRUE(verified.verifications[2].accepted);
    EXPECT_FALSE(verified.verifications[0].accepted || verified.verifications[3].accepted);
    ASSERT_EQ(verified.loop(), 2u);
    DetectorConfig floor_1 = detector;
    floor_1.verification.acceptance.min_constraining_points = 1;
    ExpectSameVerdict(verified.verifications[2], Verified(ranked, floor_1).verifications[2], 2);
    std::sort(asked.begin(), asked.end());
    EXPECT_EQ(asked,
              (std::vector<std::pair<std::size_t, std::size_t>>{{4, 0}, {4, 1}, {4, 2}, {4, 3}}));
}

// VerifyQuery registers with the poses the check allows, and so with the odometry's degeneracy
// floor, exactly the candidates whose pose the check judges.
TEST(OdometryFloor, OnlyTheCandidatesWhosePoseTheCheckJudges) {
    DetectorConfig detector = OnlyTheOdometryPins();
    detector.stop_at_first_loop = false;
    const RankedCandidates ranked = MakeRankedCandidates(detector);
    std::vector<std::pair<std::size_t, std::size_t>> asked;
    const auto any_pose = [](const core::Transform& /*unused*/) { return true; };
    const LoopCheck judges_candidate_2{
        [](LoopQuery& /*unused*/) {},
        [&](std::size_t query, std::size_t match) -> registration::PoseAllowed {
            asked.emplace_back(query, match);
            if (match == 2) return any_pose;
            return {};
        },
        {},
        {},
        {},
        {},
        {},
        {},
        {}};
    ExpectOnlyCandidate2HadTheLooserFloor(ranked, detector, judges_candidate_2, asked);
}

// VerifyQuery registers with the motion's degeneracy floor exactly the candidates the scans' own
// motion judges (LoopCheck::motion_judges), and with min_constraining_points the others.
TEST(MotionFloor, OnlyTheCandidatesAChainJoinsToTheQuery) {
    DetectorConfig detector = Verifying();
    detector.stop_at_first_loop = false;
    detector.verification.acceptance.min_constraining_points = 1'000'000;
    detector.verification.acceptance.min_constraining_points_with_motion = 1;
    const RankedCandidates ranked = MakeRankedCandidates(detector);
    std::vector<std::pair<std::size_t, std::size_t>> asked;
    LoopCheck chain_joins_2;
    chain_joins_2.reject = [](LoopQuery& /*unused*/) {};
    chain_joins_2.motion_judges = [&](std::size_t query, std::size_t match) {
        asked.emplace_back(query, match);
        return match == 2;
    };
    ExpectOnlyCandidate2HadTheLooserFloor(ranked, detector, chain_joins_2, asked);
}

}  // namespace
}  // namespace lidarloop::pipeline
