#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <random>

#include <gtest/gtest.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/pipeline/descriptor_method.hpp"
#include "lidarloop/pipeline/histogram_method.hpp"
#include "lidarloop/pipeline/loop_detector.hpp"
#include "lidarloop/pipeline/sequence.hpp"
#include "pipeline/pipeline_test_utils.hpp"
#include "test_utils.hpp"

namespace lidarloop::pipeline {
namespace {

core::DescriptorConfig HeightConfig(int bins) {
    core::DescriptorConfig config;
    config.method = core::Method::kHeight;
    config.histogram.bins = bins;
    return config;
}

// `detector` deciding with `threshold` instead of the method's default.
DetectorConfig Deciding(DetectorConfig detector, double threshold) {
    detector.threshold = threshold;
    return detector;
}

void ExpectSameQueries(const LoopQuery& online, const LoopQuery& offline) {
    EXPECT_EQ(online.query, offline.query);
    ASSERT_EQ(online.candidates.size(), offline.candidates.size()) << "query " << online.query;
    for (std::size_t r = 0; r < online.candidates.size(); ++r) {
        EXPECT_EQ(online.candidates[r].index, offline.candidates[r].index) << online.query;
        // The matrix stores float; the online path keeps double.
        EXPECT_NEAR(online.candidates[r].distance, offline.candidates[r].distance,
                    1e-6 * online.candidates[r].distance + 1e-9);
    }
    EXPECT_EQ(online.accepted, offline.accepted) << online.query;
    if (std::isnan(online.second_ratio)) {
        EXPECT_TRUE(std::isnan(offline.second_ratio)) << online.query;
    } else {
        EXPECT_NEAR(online.second_ratio, offline.second_ratio, 1e-5) << online.query;
    }
}

void CheckOnlineEqualsOffline(const DetectorConfig& detector, unsigned seed) {
    const auto histograms = test::ClusteredHistograms(400, 40, 25, seed);
    const core::DescriptorConfig config = HeightConfig(40);
    LoopDetector online(config, Deciding(detector, 0.01));
    std::vector<LoopQuery> online_results;
    std::vector<double> times;
    for (std::size_t i = 0; i < histograms.size(); ++i) {
        times.push_back(0.1 * static_cast<double>(i) + (i % 3 == 0 ? 0.05 : 0.0));
        online_results.push_back(
            online.Process(test::HistogramDescriptor(histograms[i]), times[i]));
    }
    const SimilarityMatrix matrix = ComputeSimilarityMatrix(online.database());
    const auto offline = DetectFromMatrix(matrix, times, Deciding(detector, online.threshold()),
                                          core::Method::kHeight);
    ASSERT_EQ(offline.size(), online_results.size());
    std::size_t with_match = 0;
    for (std::size_t i = 0; i < offline.size(); ++i) {
        ExpectSameQueries(online_results[i], offline[i]);
        with_match += offline[i].has_match();
    }
    EXPECT_GT(with_match, 300U);
}

TEST(LoopDetector, OnlineEqualsOfflineWithGapInScans) {
    DetectorConfig detector;
    detector.min_gap = {30.0, core::MinGap::Unit::kScans};
    detector.top_k = 5;
    CheckOnlineEqualsOffline(detector, 5);
}

TEST(LoopDetector, OnlineEqualsOfflineWithGapInSeconds) {
    DetectorConfig detector;
    detector.min_gap = {2.5, core::MinGap::Unit::kSeconds};
    detector.top_k = 3;
    CheckOnlineEqualsOffline(detector, 6);
}

TEST(LoopDetector, CandidatesRespectTheGapAndThreshold) {
    const auto histograms = test::ClusteredHistograms(100, 20, 3, 7);
    DetectorConfig detector;
    detector.min_gap = {10.0, core::MinGap::Unit::kScans};
    LoopDetector online(HeightConfig(20), Deciding(detector, 1.0));  // tau = 1 accepts everything
    for (std::size_t i = 0; i < histograms.size(); ++i) {
        const LoopQuery q = online.Process(test::HistogramDescriptor(histograms[i]), 0.0);
        EXPECT_EQ(q.has_match(), i > 10) << i;
        for (const Neighbor& n : q.candidates) EXPECT_GT(i - n.index, 10U);
        if (q.has_match()) {
            EXPECT_TRUE(q.accepted);
        }
    }
    LoopDetector strict(HeightConfig(20),
                        Deciding(detector, 0.0));  // tau = 0 accepts only equal scans
    for (std::size_t i = 0; i < 30; ++i) {
        const LoopQuery q = strict.Process(test::HistogramDescriptor(histograms[i]), 0.0);
        if (q.has_match()) {
            EXPECT_EQ(q.accepted, q.candidates.front().distance == 0.0);
        }
    }
}

TEST(LoopDetector, QueryOnlyDoesNotInsertAndSeesEveryScan) {
    const auto histograms = test::ClusteredHistograms(50, 20, 5, 8);
    LoopDetector detector(HeightConfig(20), Deciding(DetectorConfig{}, 0.01));
    for (const auto& h : histograms) detector.Process(test::HistogramDescriptor(h), 0.0);
    const LoopQuery q = detector.Query(test::HistogramDescriptor(histograms[49]));
    EXPECT_EQ(detector.database().size(), 50U);
    ASSERT_TRUE(q.has_match());
    EXPECT_EQ(q.candidates.front().index, 49U);  // itself, which the gap would exclude online
    EXPECT_EQ(q.candidates.front().distance, 0.0);
}

// The gap in seconds counts back in time: a NaN time, or one before the scan before's, is an
// error that stores nothing (a map's scans may be of any time).
TEST(LoopDetector, ATimeThatIsNaNOrGoesBackIsAnError) {
    const auto histograms = test::ClusteredHistograms(4, 20, 2, 2);
    DescriptorDatabase map(HeightConfig(20));
    map.Add(test::HistogramDescriptor(histograms[0]), 100.0);
    EXPECT_THROW(map.Add(test::HistogramDescriptor(histograms[1]), std::nan("")),
                 core::ConfigError);
    EXPECT_THROW(map.AddMissing(std::numeric_limits<double>::infinity()), core::ConfigError);
    EXPECT_EQ(map.size(), 1U);
    LoopDetector detector(std::move(map), Deciding(DetectorConfig{}, 0.01));
    detector.Process(test::HistogramDescriptor(histograms[1]), 5.0);  // before the map: allowed
    detector.Process(test::HistogramDescriptor(histograms[2]), 5.0);  // the same time: allowed
    EXPECT_THROW(detector.Process(test::HistogramDescriptor(histograms[3]), 4.9),
                 core::ConfigError);
    EXPECT_THROW(detector.Process(test::HistogramDescriptor(histograms[3]), std::nan("")),
                 core::ConfigError);
    EXPECT_EQ(detector.database().size(), 3U);
    detector.Process(test::HistogramDescriptor(histograms[3]), 6.0);
    EXPECT_EQ(detector.database().size(), 4U);
}

TEST(LoopDetector, ALoadedDatabaseNeverOffersAMissingScan) {
    DescriptorDatabase database(HeightConfig(20));
    const auto histograms = test::ClusteredHistograms(30, 20, 3, 4);
    for (std::size_t i = 0; i < histograms.size(); ++i) {
        if (i == 11) {
            database.AddMissing(0.0);  // stored as a row of zeros
        } else {
            database.Add(test::HistogramDescriptor(histograms[i]), 0.0);
        }
    }
    const LoopDetector detector(std::move(database), Deciding(DetectorConfig{}, 1.0));
    // All mass in the last bucket: its cumulative row is nearly the zero row of the missing scan.
    std::vector<double> last_bucket(20, 0.0);
    last_bucket.back() = 1.0;
    const LoopQuery q = detector.Query(test::HistogramDescriptor(last_bucket));
    ASSERT_EQ(q.candidates.size(), static_cast<std::size_t>(DetectorConfig{}.top_k));
    for (const Neighbor& c : q.candidates) EXPECT_NE(c.index, 11U);
}

TEST(LocaliseSequence, EqualsBruteForceAgainstTheMap) {
    const auto histograms = test::ClusteredHistograms(300, 30, 12, 21);
    DescriptorDatabase map(HeightConfig(30));
    DescriptorDatabase queries(HeightConfig(30));
    for (std::size_t i = 0; i < histograms.size(); ++i) {
        auto& target = i % 3 == 0 ? queries : map;
        if (i % 37 == 5) {
            target.AddMissing(0.0);
        } else {
            target.Add(test::HistogramDescriptor(histograms[i]), 0.0);
        }
    }
    DetectorConfig config;
    config.top_k = 4;
    config.min_gap = {3.0, core::MinGap::Unit::kScans};
    const LoopDetector detector(DescriptorDatabase(map), Deciding(config, 0.01));
    const auto parallel = LocaliseSequence(detector, queries);
    const auto serial = LocaliseSequence(detector, queries, Execution::kSerial);
    ASSERT_EQ(parallel.size(), queries.size());
    std::size_t matched = 0;
    for (std::size_t i = 0; i < queries.size(); ++i) {
        ExpectSameQueries(parallel[i], serial[i]);
        if (!queries.IsValid(i)) {
            EXPECT_FALSE(parallel[i].has_match()) << i;
            continue;
        }
        const std::unique_ptr<PreparedQuery> query = queries.PrepareStored(i);
        const auto expected = NearestCandidates(
            map.size(), 4, [&](std::size_t j) { return map.Distance(*query, j); },
            [&](std::size_t j) { return map.IsValid(j); });
        ASSERT_EQ(parallel[i].candidates.size(), expected.size()) << i;
        for (std::size_t r = 0; r < expected.size(); ++r) {
            EXPECT_EQ(parallel[i].candidates[r].index, expected[r].index) << i;
        }
        matched += parallel[i].has_match();
    }
    EXPECT_GT(matched, 90U);
}

TEST(LocaliseSequence, RefusesQueriesDescribedDifferently) {
    const LoopDetector detector(HeightConfig(30), Deciding(DetectorConfig{}, 0.01));
    EXPECT_THROW(LocaliseSequence(detector, DescriptorDatabase(HeightConfig(31))),
                 core::ConfigError);
    EXPECT_NO_THROW(LocaliseSequence(detector, DescriptorDatabase(HeightConfig(30))));
}

TEST(LoopDetector, NdtUsesTheSameRules) {
    core::DescriptorConfig config;
    config.method = core::Method::kNdt;
    DetectorConfig detector;
    detector.min_gap = {2.0, core::MinGap::Unit::kScans};
    detector.verify = false;  // the descriptor's decisions, as DetectFromMatrix makes them
    LoopDetector online(config, detector);
    std::vector<double> times;
    std::vector<LoopQuery> results;
    for (unsigned i = 0; i < 10; ++i) {
        times.push_back(i);
        results.push_back(online.Process(test::RandomCloud(2000, i % 4, 3.0f), times.back()));
    }
    const auto offline = DetectFromMatrix(ComputeSimilarityMatrix(online.database()), times,
                                          detector, core::Method::kNdt);
    EXPECT_EQ(online.threshold(), DefaultThreshold(core::Method::kNdt));
    for (std::size_t i = 0; i < results.size(); ++i) ExpectSameQueries(results[i], offline[i]);
    // Scan 4 repeats scan 0 (same seed): found with distance 0.
    ASSERT_TRUE(results[4].has_match());
    EXPECT_EQ(results[4].candidates.front().index, 0U);
    EXPECT_EQ(results[4].candidates.front().distance, 0.0);
}

// The bounded heap against sorting every eligible scan, with ties, missing (+inf) scans and k
// from 0 to beyond the count.
// A verified query's loop is the accepted candidate that overlaps best, not the first accepted
// in descriptor order: it shares most of the view (docs/verification.md).
TEST(LoopQuery, TheLoopIsTheAcceptedCandidateThatOverlapsBest) {
    const auto verdict = [](bool accepted, double overlap) {
        registration::Verification v;
        v.accepted = accepted;
        v.overlap.query_fraction = overlap;
        v.overlap.match_fraction = overlap + 0.1;  // the score is the smaller fraction
        return v;
    };
    LoopQuery q;
    q.candidates = {{7, 0.1}, {3, 0.2}, {5, 0.3}, {1, 0.4}};
    q.verifications = {verdict(false, 0.9), verdict(true, 0.4), verdict(true, 0.7),
                       verdict(true, 0.7)};
    EXPECT_EQ(q.loop(), std::optional<std::size_t>(2));  // the first of two equal overlaps
    q.verifications[2].accepted = false;
    EXPECT_EQ(q.loop(), std::optional<std::size_t>(3));
    for (auto& v : q.verifications) v.accepted = false;
    EXPECT_EQ(q.loop(), std::nullopt);
    q.verifications.clear();  // descriptor only: the best candidate when accepted
    q.accepted = true;
    EXPECT_EQ(q.loop(), std::optional<std::size_t>(0));
    q.accepted = false;
    EXPECT_EQ(q.loop(), std::nullopt);
}

TEST(NearestCandidates, EqualsSortingEveryEligibleScan) {
    std::mt19937 rng(7);
    std::uniform_int_distribution<int> level(0, 6);  // few levels: many ties
    for (std::size_t count : {0U, 1U, 5U, 40U}) {
        std::vector<double> distances(count);
        for (double& d : distances) {
            const int l = level(rng);
            d = l == 6 ? HUGE_VAL : 0.1 * l;
        }
        const auto eligible = [](std::size_t j) { return j % 7 != 3; };
        std::vector<Neighbor> all;
        for (std::size_t j = 0; j < count; ++j) {
            if (eligible(j) && distances[j] < HUGE_VAL) all.push_back({j, distances[j]});
        }
        std::stable_sort(all.begin(), all.end(), [](const Neighbor& a, const Neighbor& b) {
            return a.distance < b.distance;
        });
        for (std::size_t k = 0; k <= count + 2; ++k) {
            const auto got = NearestCandidates(
                count, k, [&](std::size_t j) { return distances[j]; }, eligible);
            ASSERT_EQ(got.size(), std::min(k, all.size())) << count << " " << k;
            for (std::size_t r = 0; r < got.size(); ++r) {
                EXPECT_EQ(got[r].index, all[r].index) << count << " " << k << " " << r;
                EXPECT_EQ(got[r].distance, all[r].distance);
            }
        }
    }
}

void ExpectIdenticalQueries(const std::vector<LoopQuery>& a, const std::vector<LoopQuery>& b) {
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        ASSERT_EQ(a[i].query, b[i].query);
        ASSERT_EQ(a[i].candidates.size(), b[i].candidates.size()) << i;
        for (std::size_t r = 0; r < a[i].candidates.size(); ++r) {
            EXPECT_EQ(a[i].candidates[r].index, b[i].candidates[r].index) << i;
            EXPECT_EQ(a[i].candidates[r].distance, b[i].candidates[r].distance) << i;
        }
        EXPECT_EQ(a[i].accepted, b[i].accepted) << i;
        EXPECT_TRUE(a[i].second_ratio == b[i].second_ratio ||
                    (std::isnan(a[i].second_ratio) && std::isnan(b[i].second_ratio)))
            << i;
    }
}

// Detection without the matrix gives exactly what detection from the matrix gives: the same
// float-rounded distances, candidates, second ratios and decisions.
TEST(DetectStreaming, EqualsDetectFromMatrixExactly) {
    const auto histograms = test::ClusteredHistograms(300, 40, 20, 3);
    DescriptorDatabase database(HeightConfig(40));
    for (std::size_t i = 0; i < histograms.size(); ++i) {
        const double time_s = 0.1 * static_cast<double>(i) + (i % 3 == 0 ? 0.05 : 0.0);
        if (i % 50 == 7) {
            database.AddMissing(time_s);
        } else {
            database.Add(test::HistogramDescriptor(histograms[i]), time_s);
        }
    }
    const SimilarityMatrix matrix = ComputeSimilarityMatrix(database);
    for (const core::MinGap gap : {core::MinGap{30.0, core::MinGap::Unit::kScans},
                                   core::MinGap{2.5, core::MinGap::Unit::kSeconds},
                                   core::MinGap{0.0, core::MinGap::Unit::kScans}}) {
        DetectorConfig detector = Deciding(DetectorConfig{}, 0.01);
        detector.min_gap = gap;
        detector.top_k = 4;
        const auto expected =
            DetectFromMatrix(matrix, database.times_s(), detector, core::Method::kHeight);
        ExpectIdenticalQueries(DetectStreaming(database, detector), expected);
        ExpectIdenticalQueries(DetectStreaming(database, detector, Execution::kSerial), expected);
    }
}

std::vector<std::size_t> IndicesOf(const std::vector<Neighbor>& candidates) {
    std::vector<std::size_t> indices;
    for (const Neighbor& n : candidates) indices.push_back(n.index);
    return indices;
}

// 300 height histograms of 20 places, 0.1 s apart, described.
DescriptorDatabase ClusteredDatabase() {
    const auto histograms = test::ClusteredHistograms(300, 40, 20, 3);
    DescriptorDatabase database(HeightConfig(40));
    for (std::size_t i = 0; i < histograms.size(); ++i)
        database.Add(test::HistogramDescriptor(histograms[i]), 0.1 * static_cast<double>(i));
    return database;
}

// A synthetic odometry's reach: about a third of the pairs are out of it.
bool InSyntheticReach(std::size_t query, std::size_t match) { return (query + 2 * match) % 3 != 0; }

// Brute force over the matrix: the scans more than 30 before `query` in the synthetic reach, by
// (distance, index), at most `count` (all scans more than 30 before without `within_reach`).
std::vector<Neighbor> RankedInReach(const SimilarityMatrix& matrix, std::size_t query,
                                    std::size_t count, bool within_reach = true) {
    std::vector<Neighbor> ranked;
    for (std::size_t j = 0; j + 30 < query; ++j) {
        if (!within_reach || InSyntheticReach(query, j))
            ranked.push_back({j, double{matrix.at(query, j)}});
    }
    std::sort(ranked.begin(), ranked.end(), [](const Neighbor& a, const Neighbor& b) {
        return a.distance < b.distance || (a.distance == b.distance && a.index < b.index);
    });
    ranked.resize(std::min(ranked.size(), count));
    return ranked;
}

// A check that says some scans cannot close a loop with the query (the odometry puts them out of
// reach) makes them no candidates: the top k are the best k the check keeps, as brute force over
// the matrix ranks them. The check judges only the scans that rank high enough to matter.
TEST(DetectFromMatrix, ScansOutOfTheChecksReachAreNoCandidates) {
    const DescriptorDatabase database = ClusteredDatabase();
    const SimilarityMatrix matrix = ComputeSimilarityMatrix(database);
    DetectorConfig detector = Deciding(DetectorConfig{}, 0.01);
    detector.top_k = 4;
    const double max_loop_m = detector.verification.acceptance.max_loop_distance_m;
    std::atomic<std::size_t> judged{0};
    LoopCheck check;
    check.may_close = [&](std::size_t query, std::size_t match, double max_loop_distance_m) {
        EXPECT_EQ(max_loop_distance_m, max_loop_m);
        ++judged;
        return InSyntheticReach(query, match);
    };
    const std::vector<LoopQuery> detected =
        DetectFromMatrix(matrix, database.times_s(), detector, core::Method::kHeight, {}, check);
    const std::size_t judged_by_matrix = judged;
    std::size_t eligible_pairs = 0;
    std::size_t differ_from_unchecked = 0;
    const std::vector<LoopQuery> unchecked =
        DetectFromMatrix(matrix, database.times_s(), detector, core::Method::kHeight);
    for (std::size_t i = 0; i < matrix.size(); ++i) {
        eligible_pairs += i > 30 ? i - 30 : 0;
        const std::vector<Neighbor> expected = RankedInReach(matrix, i, 4);
        ASSERT_EQ(detected[i].candidates.size(), expected.size()) << i;
        for (std::size_t r = 0; r < expected.size(); ++r)
            EXPECT_EQ(detected[i].candidates[r].index, expected[r].index) << i << " rank " << r;
        const std::vector<Neighbor>& plain = unchecked[i].candidates;
        if (plain.size() == expected.size() && IndicesOf(plain) != IndicesOf(expected))
            ++differ_from_unchecked;
    }
    EXPECT_GT(differ_from_unchecked, 100u);  // the check changed the candidates
    EXPECT_LT(judged_by_matrix, eligible_pairs / 4);
    ExpectIdenticalQueries(DetectStreaming(database, detector, Execution::kParallel, {}, check),
                           detected);
    ExpectIdenticalQueries(DetectStreaming(database, detector, Execution::kSerial, {}, check),
                           detected);
}

// Three laps of a circle of 50 m radius, 100 scans a lap, each facing along the circle, with
// clustered histograms; the gate wants a loop's pose within 3 m of the odometry's. Fed to an
// online detector with the odometry, and the same as an offline check.
struct OdometryLaps {
    OdometryLaps() : histograms(test::ClusteredHistograms(240, 40, 12, 8)) {
        for (std::size_t i = 0; i < histograms.size(); ++i) {
            const double angle = 2.0 * M_PI * static_cast<double>(i) / 100.0;
            core::Transform T = core::Transform::Identity();
            T.linear() = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
            T.translation() = Eigen::Vector3d(50.0 * std::cos(angle), 50.0 * std::sin(angle), 0.0);
            T_odom_sensor.push_back(T);
            path_m.push_back(50.0 * angle);
            times_s.push_back(0.1 * static_cast<double>(i));
        }
    }

    // Every scan through `online` with its odometry pose; `prepared_of(i)`: scan i prepared.
    std::vector<LoopQuery> RunOnline(
        LoopDetector& online,
        const std::function<registration::PreparedScan(std::size_t)>& prepared_of) const {
        online.SetOdometryGate(gate);
        std::vector<LoopQuery> results;
        for (std::size_t i = 0; i < histograms.size(); ++i) {
            results.push_back(online.Process(test::HistogramDescriptor(histograms[i]), times_s[i],
                                             prepared_of(i), T_odom_sensor[i]));
        }
        return results;
    }

    LoopCheck Check(std::function<Eigen::Vector3d(std::size_t)> view_centre_of = {}) const {
        return CheckAgainstOdometry([this](std::size_t j) { return T_odom_sensor[j]; },
                                    [this](std::size_t j) { return path_m[j]; }, gate, nullptr,
                                    std::move(view_centre_of));
    }

    std::vector<std::vector<double>> histograms;
    std::vector<core::Transform> T_odom_sensor;
    std::vector<double> path_m;
    std::vector<double> times_s;
    // Passes a loop within 3 m of the odometry's pose, which it says (the candidate search
    // then skips the scans out of reach without ranking them).
    OdometryGate gate{[](const core::Transform& T_loop, const core::Transform& T_odometry, double) {
                          return (T_loop.translation() - T_odometry.translation()).norm() > 3.0;
                      },
                      [](double) { return 3.0; },
                      {}};
};

// Online with an odometry gate, the scans the odometry puts out of a loop's reach are no
// candidates, as offline with the same gate's check (CheckAgainstOdometry).
TEST(LoopDetector, TheOdometrysReachLimitsTheCandidatesAsOffline) {
    const OdometryLaps laps;
    DetectorConfig detector = Deciding(DetectorConfig{}, 0.01);
    detector.top_k = 3;
    detector.min_path_m = 0.0;
    LoopDetector online(HeightConfig(40), detector);
    const auto online_results =
        laps.RunOnline(online, [](std::size_t) { return registration::PreparedScan{}; });
    const SimilarityMatrix matrix = ComputeSimilarityMatrix(online.database());
    const auto offline =
        DetectFromMatrix(matrix, laps.times_s, Deciding(detector, online.threshold()),
                         core::Method::kHeight, laps.path_m, laps.Check());
    std::size_t with_candidates = 0;
    for (std::size_t i = 0; i < offline.size(); ++i) {
        ExpectSameQueries(online_results[i], offline[i]);
        with_candidates += offline[i].has_match() ? 1 : 0;
        for (const Neighbor& n : offline[i].candidates) {
            EXPECT_LE(
                (laps.T_odom_sensor[i].translation() - laps.T_odom_sensor[n.index].translation())
                    .norm(),
                detector.verification.acceptance.max_loop_distance_m + 3.0)
                << i << " " << n.index;
        }
    }
    EXPECT_GT(with_candidates, 100u);  // the second and third laps
    // The gate's allowance lets the search skip the scans out of reach before ranking them
    // (LoopCheck::in_reach_bound): the same candidates as judging every ranked scan exactly,
    // with fewer exact judgements.
    std::size_t judged_bounded = 0;
    std::size_t judged_exactly = 0;
    const auto counting = [&laps](std::size_t& judged, bool bounded) {
        LoopCheck check = laps.Check();
        if (!bounded) check.in_reach_bound = nullptr;
        check.may_close = [&judged, exact = check.may_close](std::size_t q, std::size_t m,
                                                             double max_loop_distance_m) {
            ++judged;
            return exact(q, m, max_loop_distance_m);
        };
        return check;
    };
    const DetectorConfig serial = Deciding(detector, online.threshold());
    const auto bounded = DetectFromMatrix(matrix, laps.times_s, serial, core::Method::kHeight,
                                          laps.path_m, counting(judged_bounded, true));
    const auto exactly = DetectFromMatrix(matrix, laps.times_s, serial, core::Method::kHeight,
                                          laps.path_m, counting(judged_exactly, false));
    ExpectIdenticalQueries(bounded, exactly);
    ExpectIdenticalQueries(bounded, offline);
    EXPECT_LT(judged_bounded, judged_exactly / 2);
}

// A synthetic score of a pair for ordering a shortlist: many ties, and unknown (NaN) for every
// 7th match.
double TiedScore(std::size_t query, std::size_t match) {
    if (match % 7 == 0) return std::numeric_limits<double>::quiet_NaN();
    return static_cast<double>((query * 31 + match * 17) % 10);
}

// Brute force of an ordered shortlist: the first `count` of `ranked` by `key`, smallest first, a
// NaN key after every known one, scans the explicit threshold `tau` prunes (distance above it)
// after all others, ties in rank order.
std::vector<Neighbor> OrderedShortlist(std::vector<Neighbor> ranked,
                                       const std::function<double(const Neighbor&)>& key,
                                       double tau, std::size_t count) {
    const auto sort_key = [&](const Neighbor& n) {
        const double k = key(n);
        return (std::isnan(k) ? 1e9 : k) + (n.distance > tau ? 1e12 : 0.0);
    };
    std::stable_sort(ranked.begin(), ranked.end(), [&](const Neighbor& a, const Neighbor& b) {
        return sort_key(a) < sort_key(b);
    });
    ranked.resize(std::min(ranked.size(), count));
    return ranked;
}

// Where the check knows the view distances, the top k are the k nearest views among the
// odometry_shortlist best-ranked scans within reach, nearest first (a scan of unknown distance
// last, ties in rank order): brute force over the matrix.
TEST(DetectFromMatrix, TheOdometryOrdersTheShortlistByViewDistance) {
    const DescriptorDatabase database = ClusteredDatabase();
    const SimilarityMatrix matrix = ComputeSimilarityMatrix(database);
    DetectorConfig detector = Deciding(DetectorConfig{}, 0.01);
    detector.top_k = 4;
    detector.odometry_shortlist = 12;
    const auto view_distance_m = TiedScore;
    LoopCheck check;
    check.may_close = [](std::size_t query, std::size_t match, double) {
        return InSyntheticReach(query, match);
    };
    check.view_distance_m = view_distance_m;
    const std::vector<LoopQuery> detected =
        DetectFromMatrix(matrix, database.times_s(), detector, core::Method::kHeight, {}, check);
    std::size_t reordered = 0;
    for (std::size_t i = 0; i < matrix.size(); ++i) {
        std::vector<Neighbor> ranked = RankedInReach(matrix, i, 12);
        const std::vector<Neighbor> expected = OrderedShortlist(
            ranked, [&](const Neighbor& n) { return view_distance_m(i, n.index); }, 0.01, 4);
        ASSERT_EQ(IndicesOf(detected[i].candidates), IndicesOf(expected)) << i;
        ranked.resize(std::min<std::size_t>(ranked.size(), 4));
        if (IndicesOf(ranked) != IndicesOf(expected)) ++reordered;
        // The best match (second_ratio, the descriptor's decision) is still the best-ranked.
        if (!ranked.empty()) {
            EXPECT_EQ(detected[i].accepted,
                      MethodOf(core::Method::kHeight).IsMatch(ranked.front().distance, 0.01))
                << i;
        }
    }
    EXPECT_GT(reordered, 100u);  // the order changed what is registered
    ExpectIdenticalQueries(DetectStreaming(database, detector, Execution::kParallel, {}, check),
                           detected);
    // A shortlist of top_k: the rank order, as without the view distances.
    detector.odometry_shortlist = 4;
    LoopCheck reach_only = check;
    reach_only.view_distance_m = {};
    const auto ranked_only = DetectFromMatrix(matrix, database.times_s(), detector,
                                              core::Method::kHeight, {}, reach_only);
    const auto shortlist_of_k =
        DetectFromMatrix(matrix, database.times_s(), detector, core::Method::kHeight, {}, check);
    for (std::size_t i = 0; i < matrix.size(); ++i) {
        std::vector<std::size_t> reordered_scans = IndicesOf(shortlist_of_k[i].candidates);
        std::vector<std::size_t> ranked_scans = IndicesOf(ranked_only[i].candidates);
        std::sort(reordered_scans.begin(), reordered_scans.end());
        std::sort(ranked_scans.begin(), ranked_scans.end());
        EXPECT_EQ(reordered_scans, ranked_scans) << i;  // the same scans, nearest view first
    }
}

// Without odometry, where the check knows the layouts, the top k are the k most alike among the
// layout_shortlist best-ranked scans, most alike first (a scan without a layout last, ties in
// rank order): brute force over the matrix. The view distance, where known, orders instead.
TEST(DetectFromMatrix, TheLayoutOrdersTheShortlistWithoutOdometry) {
    const DescriptorDatabase database = ClusteredDatabase();
    const SimilarityMatrix matrix = ComputeSimilarityMatrix(database);
    DetectorConfig detector = Deciding(DetectorConfig{}, 0.01);
    detector.top_k = 4;
    detector.layout_shortlist = 12;
    const auto similarity = [](std::size_t query, std::size_t match) {
        return 0.1 * TiedScore(query, match);
    };
    LoopCheck check;
    check.layout_similarity = similarity;
    const std::vector<LoopQuery> detected =
        DetectFromMatrix(matrix, database.times_s(), detector, core::Method::kHeight, {}, check);
    const std::vector<LoopQuery> ranked_only =
        DetectFromMatrix(matrix, database.times_s(), detector, core::Method::kHeight);
    std::size_t reordered = 0;
    for (std::size_t i = 0; i < matrix.size(); ++i) {
        const std::vector<Neighbor> ranked = RankedInReach(matrix, i, 12, false);
        const std::vector<Neighbor> expected = OrderedShortlist(
            ranked, [&](const Neighbor& n) { return -similarity(i, n.index); }, 0.01, 4);
        ASSERT_EQ(IndicesOf(detected[i].candidates), IndicesOf(expected)) << i;
        // Offline every query is kept: no room left for the 12 of the shortlist.
        EXPECT_EQ(detected[i].candidates.capacity(), detected[i].candidates.size()) << i;
        if (IndicesOf(ranked_only[i].candidates) != IndicesOf(expected)) ++reordered;
        EXPECT_EQ(detected[i].accepted, ranked_only[i].accepted) << i;  // the descriptor decides
    }
    EXPECT_GT(reordered, 100u);
    ExpectIdenticalQueries(DetectStreaming(database, detector, Execution::kParallel, {}, check),
                           detected);
    // layout_shortlist 0: the rank order.
    detector.layout_shortlist = 0;
    ExpectIdenticalQueries(
        DetectFromMatrix(matrix, database.times_s(), detector, core::Method::kHeight, {}, check),
        ranked_only);
    // The odometry's view distance orders where it is known, whatever the layouts.
    detector.layout_shortlist = 12;
    LoopCheck both = check;
    both.view_distance_m = [](std::size_t, std::size_t match) {
        return static_cast<double>(match % 5);
    };
    LoopCheck views_only = both;
    views_only.layout_similarity = {};
    ExpectIdenticalQueries(
        DetectFromMatrix(matrix, database.times_s(), detector, core::Method::kHeight, {}, both),
        DetectFromMatrix(matrix, database.times_s(), detector, core::Method::kHeight, {},
                         views_only));
}

// A prepared scan that looks at `centre`, with a few structure points there (too few to
// register: verification rejects it at once).
registration::PreparedScan LookingAt(const Eigen::Vector3d& centre) {
    const Eigen::Vector3f c = centre.cast<float>();
    std::vector<Eigen::Vector3f> points{c + Eigen::Vector3f(1, 0, 0), c - Eigen::Vector3f(1, 0, 0),
                                        c};
    std::vector<Eigen::Vector3f> normals(points.size(), Eigen::Vector3f::UnitX());
    registration::PreparedScan scan;
    scan.structure =
        std::make_shared<const registration::SurfacePoints>(std::move(points), std::move(normals));
    scan.view_centre = centre;
    return scan;
}

// Online with an odometry gate, a query's candidates are ordered by the odometry's distance of
// the scans' view centres, as offline with the same check (CheckAgainstOdometry with the view
// centres).
TEST(LoopDetector, TheOdometryOrdersTheCandidatesByViewAsOffline) {
    const OdometryLaps laps;
    std::vector<Eigen::Vector3d> view_centres;  // looking 0-20 m ahead
    for (std::size_t i = 0; i < laps.histograms.size(); ++i)
        view_centres.emplace_back(static_cast<double>((i * 7) % 21), 0.0, 0.0);
    DetectorConfig detector = Deciding(DetectorConfig{}, 0.01);
    detector.top_k = 3;
    detector.odometry_shortlist = 8;
    detector.min_path_m = 0.0;
    LoopDetector online(HeightConfig(40), detector);
    const auto online_results =
        laps.RunOnline(online, [&](std::size_t i) { return LookingAt(view_centres[i]); });
    const SimilarityMatrix matrix = ComputeSimilarityMatrix(online.database());
    const auto offline = DetectFromMatrix(
        matrix, laps.times_s, Deciding(detector, online.threshold()), core::Method::kHeight,
        laps.path_m, laps.Check([&](std::size_t j) { return view_centres[j]; }));
    std::size_t ordered = 0;
    for (std::size_t i = 0; i < offline.size(); ++i) {
        EXPECT_EQ(IndicesOf(online_results[i].candidates), IndicesOf(offline[i].candidates)) << i;
        const auto view_distance = [&](const Neighbor& n) {
            return (laps.T_odom_sensor[i] * view_centres[i] -
                    laps.T_odom_sensor[n.index] * view_centres[n.index])
                .norm();
        };
        // Nearest first among the scans the threshold keeps, then among those it prunes.
        const auto key = [&](const Neighbor& n) {
            return view_distance(n) + (n.distance > online.threshold() ? 1e12 : 0.0);
        };
        const auto& candidates = offline[i].candidates;
        for (std::size_t r = 1; r < candidates.size(); ++r)
            EXPECT_LE(key(candidates[r - 1]), key(candidates[r])) << i;
        ordered += candidates.size() > 1 ? 1 : 0;
    }
    EXPECT_GT(ordered, 100u);
}

// Many scans with equal descriptors: ties at the k-th place, where the index's answer is not
// enough and the search compares every eligible scan instead.
TEST(DetectStreaming, EqualsDetectFromMatrixWithManyTies) {
    const auto patterns = test::ClusteredHistograms(10, 30, 5, 11);
    DescriptorDatabase database(HeightConfig(30));
    for (std::size_t i = 0; i < 200; ++i)
        database.Add(test::HistogramDescriptor(patterns[i % patterns.size()]),
                     0.1 * static_cast<double>(i));
    DetectorConfig detector = Deciding(DetectorConfig{}, 0.01);
    detector.min_gap = {5.0, core::MinGap::Unit::kScans};
    ExpectIdenticalQueries(DetectStreaming(database, detector),
                           DetectFromMatrix(ComputeSimilarityMatrix(database), database.times_s(),
                                            detector, core::Method::kHeight));
}

TEST(DetectStreaming, EqualsDetectFromMatrixForNdt) {
    core::DescriptorConfig config;
    config.method = core::Method::kNdt;
    DescriptorDatabase database(config);
    for (unsigned i = 0; i < 12; ++i) {
        database.Add(ComputeDescriptor(test::RandomCloud(2000, i % 4, 3.0f), config), i);
    }
    DetectorConfig detector;
    detector.min_gap = {2.0, core::MinGap::Unit::kScans};
    ExpectIdenticalQueries(DetectStreaming(database, detector),
                           DetectFromMatrix(ComputeSimilarityMatrix(database), database.times_s(),
                                            detector, core::Method::kNdt));
}

// A slow platform: 40 scans driven 2 m apart, then 80 scans creeping 5 cm apart that all look
// like the query; scan 5 looks like it too, a little less. Returns the database (the query is
// the last scan, 120) and the scans' cumulative path, metres.
std::vector<core::Descriptor> SlowPlatformScans(std::vector<double>& path_m) {
    std::mt19937 rng(21);
    std::normal_distribution<double> noise(0.0, 1.0);
    std::exponential_distribution<double> weight(1.0);
    const auto place = [&] {
        std::vector<double> h(40);
        for (double& v : h) v = weight(rng);
        return h;
    };
    const std::vector<double> here = place();
    const auto near_here = [&](double spread) {
        std::vector<double> h = here;
        for (double& v : h) v = std::max(0.0, v + spread * noise(rng));
        return h;
    };
    std::vector<core::Descriptor> scans;
    for (std::size_t i = 0; i <= 120; ++i) {
        const bool creeping = i >= 40;
        path_m.push_back(i == 0 ? 0.0 : path_m.back() + (creeping ? 0.05 : 2.0));
        const std::vector<double> h = i == 120   ? here
                                      : creeping ? near_here(0.001)
                                      : i == 5   ? near_here(0.02)
                                                 : place();
        scans.push_back(test::HistogramDescriptor(h));
    }
    return scans;
}

// `scans` stored, scan i at 0.1 i seconds.
DescriptorDatabase StoredAtTenHertz(const std::vector<core::Descriptor>& scans) {
    DescriptorDatabase database(HeightConfig(40));
    for (const core::Descriptor& scan : scans)
        database.Add(scan, 0.1 * static_cast<double>(database.size()));
    return database;
}

// SlowPlatformScans stored, scan i at 0.1 i seconds.
DescriptorDatabase SlowPlatform(std::vector<double>& path_m) {
    return StoredAtTenHertz(SlowPlatformScans(path_m));
}

TEST(LoopDetector, AGapInMetresKeepsTheRecentPastOutOfTheCandidates) {
    std::vector<double> path_m;
    const DescriptorDatabase database = SlowPlatform(path_m);
    const SimilarityMatrix matrix = ComputeSimilarityMatrix(database);
    DetectorConfig detector = Deciding(DetectorConfig{}, 0.01);
    detector.top_k = 5;
    detector.min_path_m = 0.0;  // the gap alone
    // 30 scans back is only 1.5 m of path: the candidates are the recent past.
    detector.min_gap = {30.0, core::MinGap::Unit::kScans};
    const LoopQuery scans =
        DetectFromMatrix(matrix, database.times_s(), detector, core::Method::kHeight, path_m)
            .back();
    ASSERT_EQ(scans.candidates.size(), 5u);
    for (const Neighbor& n : scans.candidates) EXPECT_LT(path_m[120] - path_m[n.index], 5.0);
    // 20 m of path: only the scans driven before, of which scan 5 is the place.
    detector.min_gap = {20.0, core::MinGap::Unit::kMetres};
    const std::vector<LoopQuery> metres =
        DetectFromMatrix(matrix, database.times_s(), detector, core::Method::kHeight, path_m);
    ASSERT_EQ(metres.back().candidates.size(), 5u);
    EXPECT_EQ(metres.back().candidates.front().index, 5u);
    for (const LoopQuery& q : metres) {
        for (const Neighbor& n : q.candidates) EXPECT_GT(path_m[q.query] - path_m[n.index], 20.0);
    }
    ExpectIdenticalQueries(DetectStreaming(database, detector, Execution::kParallel, path_m),
                           metres);
}

// The default: 30 scans and, where the path is known, more than 50 m of it. Without the path
// the gap alone decides.
TEST(LoopDetector, ThePathRuleKeepsTheRecentPastOutBesideAGapInScans) {
    std::vector<double> path_m;
    const std::vector<core::Descriptor> scans = SlowPlatformScans(path_m);
    const DescriptorDatabase database = StoredAtTenHertz(scans);
    const SimilarityMatrix matrix = ComputeSimilarityMatrix(database);
    DetectorConfig detector = Deciding(DetectorConfig{}, 0.01);
    detector.top_k = 5;
    ASSERT_EQ(detector.min_gap, (core::MinGap{30.0, core::MinGap::Unit::kScans}));
    ASSERT_EQ(detector.min_path_m, 50.0);
    const std::vector<LoopQuery> with_path =
        DetectFromMatrix(matrix, database.times_s(), detector, core::Method::kHeight, path_m);
    ASSERT_EQ(with_path.back().candidates.size(), 5u);
    EXPECT_EQ(with_path.back().candidates.front().index, 5u);
    std::size_t queries_with_candidates = 0;
    for (const LoopQuery& q : with_path) {
        queries_with_candidates += q.has_match() ? 1 : 0;
        for (const Neighbor& n : q.candidates) {
            EXPECT_GT(path_m[q.query] - path_m[n.index], 50.0);
            EXPECT_GT(q.query - n.index, 30u);
        }
    }
    EXPECT_GT(queries_with_candidates, 0u);
    ExpectIdenticalQueries(DetectStreaming(database, detector, Execution::kParallel, path_m),
                           with_path);
    const LoopQuery without_path =
        DetectFromMatrix(matrix, database.times_s(), detector, core::Method::kHeight).back();
    ASSERT_FALSE(without_path.candidates.empty());
    EXPECT_LT(path_m[120] - path_m[without_path.candidates.front().index], 5.0);
    // Online, the odometry gives the path: the same candidates.
    LoopDetector online(HeightConfig(40), detector);
    for (std::size_t i = 0; i < database.size(); ++i) {
        core::Transform T_odom_sensor = core::Transform::Identity();
        T_odom_sensor.translation().x() = path_m[i];
        ExpectSameQueries(online.Process(scans[i], database.times_s()[i], {}, T_odom_sensor),
                          with_path[i]);
    }
}

TEST(LoopDetector, AGapInMetresNeedsThePath) {
    std::vector<double> path_m;
    const DescriptorDatabase database = SlowPlatform(path_m);
    DetectorConfig detector = Deciding(DetectorConfig{}, 0.01);
    detector.min_gap = {20.0, core::MinGap::Unit::kMetres};
    EXPECT_THROW(DetectStreaming(database, detector), core::ConfigError);
    path_m.pop_back();
    EXPECT_THROW(DetectFromMatrix(ComputeSimilarityMatrix(database), database.times_s(), detector,
                                  core::Method::kHeight, path_m),
                 core::ConfigError);
    LoopDetector online(HeightConfig(40), detector);  // localisation needs no gap
    EXPECT_THROW(online.Process(test::HistogramDescriptor(std::vector<double>(40, 1.0)), 0.0),
                 core::ConfigError);
}

// Online, the odometry's poses give the path: the same candidates as offline with that path.
TEST(LoopDetector, OnlineWithOdometryEqualsOfflineWithTheGapInMetres) {
    std::vector<double> path_m;
    const std::vector<core::Descriptor> scans = SlowPlatformScans(path_m);
    const DescriptorDatabase database = StoredAtTenHertz(scans);
    DetectorConfig detector = Deciding(DetectorConfig{}, 0.01);
    detector.top_k = 5;
    detector.min_gap = {20.0, core::MinGap::Unit::kMetres};
    detector.min_path_m = 0.0;  // the gap alone
    const std::vector<LoopQuery> offline =
        DetectFromMatrix(ComputeSimilarityMatrix(database), database.times_s(), detector,
                         core::Method::kHeight, path_m);
    LoopDetector online(HeightConfig(40), detector);
    for (std::size_t i = 0; i < database.size(); ++i) {
        // Driving along x, turning a little: the path is the sum of the steps.
        core::Transform T_odom_sensor = core::Transform::Identity();
        T_odom_sensor.translation() << path_m[i], 0.0, 0.0;
        T_odom_sensor.linear() =
            Eigen::AngleAxisd(0.01 * static_cast<double>(i), Eigen::Vector3d::UnitZ())
                .toRotationMatrix();
        const LoopQuery query = online.Process(scans[i], database.times_s()[i], {}, T_odom_sensor);
        ExpectSameQueries(query, offline[i]);
    }
    EXPECT_EQ(offline.back().candidates.front().index, 5u);
}

// A map saved from another session, then this session's scans with their odometry: the map's
// scans (no poses) are candidates whatever the gap in metres, this session's only beyond it.
TEST(LoopDetector, AMapsScansAreCandidatesOfASessionWithOdometry) {
    std::vector<double> path_m;
    const std::vector<core::Descriptor> scans = SlowPlatformScans(path_m);
    constexpr std::size_t kMapScans = 30;  // scan 5, the place, is among them
    DescriptorDatabase map(HeightConfig(40));
    for (std::size_t i = 0; i < kMapScans; ++i) map.Add(scans[i], 0.1 * static_cast<double>(i));
    DetectorConfig detector = Deciding(DetectorConfig{}, 0.01);
    detector.top_k = 5;
    detector.min_gap = {20.0, core::MinGap::Unit::kMetres};
    detector.min_path_m = 0.0;  // the gap alone
    LoopDetector session(map, detector);
    LoopQuery last;
    for (std::size_t i = kMapScans; i < scans.size(); ++i) {
        core::Transform T_odom_sensor = core::Transform::Identity();
        T_odom_sensor.translation().x() = path_m[i];
        last = session.Process(scans[i], 0.1 * static_cast<double>(i), {}, T_odom_sensor);
        for (const Neighbor& n : last.candidates) {
            EXPECT_TRUE(n.index < kMapScans || path_m[i] - path_m[n.index] > 20.0)
                << i << " -> " << n.index;
        }
    }
    ASSERT_FALSE(last.candidates.empty());
    EXPECT_EQ(last.candidates.front().index, 5u);
    // Within the session, with and without a pose still do not mix.
    EXPECT_THROW(session.Process(scans[0], 99.0), core::ConfigError);
}

TEST(LoopDetector, RejectsBadConfigAndMixedMethods) {
    DetectorConfig detector;
    detector.top_k = 0;
    EXPECT_THROW(LoopDetector(HeightConfig(10), Deciding(detector, 0.01)), core::ConfigError);
    detector.top_k = 1;
    detector.min_gap.value = -1;
    EXPECT_THROW(LoopDetector(HeightConfig(10), Deciding(detector, 0.01)), core::ConfigError);
    for (double bad : {-0.1, std::nan(""), HUGE_VAL}) {
        EXPECT_THROW(LoopDetector(HeightConfig(10), Deciding(DetectorConfig{}, bad)),
                     core::ConfigError)
            << bad;
        DetectorConfig path_rule;
        path_rule.min_path_m = bad;
        EXPECT_THROW(LoopDetector(HeightConfig(10), Deciding(path_rule, 0.01)), core::ConfigError)
            << bad;
    }
    LoopDetector ok(HeightConfig(10), Deciding(DetectorConfig{}, 0.01));
    core::Descriptor range = test::HistogramDescriptor(std::vector<double>(10, 0.1));
    range.method = core::Method::kRange;
    EXPECT_THROW(ok.Process(range, 0.0), core::ConfigError);
    EXPECT_THROW(ok.Process(test::HistogramDescriptor(std::vector<double>(9, 0.1)), 0.0),
                 core::ConfigError);
}

ScanSource SourceWithBadScan(std::size_t count, std::size_t bad) {
    ScanSource source;
    source.count = count;
    source.load = [bad](std::size_t i) -> core::PointCloud {
        if (i == bad) throw core::Error("scans/000007.bin: size 13 bytes is not a multiple of 16");
        return test::RandomCloud(500, static_cast<unsigned>(i));
    };
    source.time_s = [](std::size_t i) { return 0.1 * static_cast<double>(i); };
    return source;
}

TEST(DescribeSequence, StopsAtABadScanNamingIt) {
    try {
        DescribeSequence(SourceWithBadScan(20, 7), HeightConfig(50));
        FAIL() << "a bad scan went unnoticed";
    } catch (const core::Error& e) {
        EXPECT_NE(std::string(e.what()).find("scan 7: scans/000007.bin: size 13"),
                  std::string::npos)
            << e.what();
    }
}

TEST(DescribeSequence, SkipsABadScanWhenAskedAndItNeverMatches) {
    DescribeOptions options;
    options.skip_bad = true;
    std::size_t last_progress = 0;
    options.execution = Execution::kSerial;
    options.progress = [&](std::size_t done, std::size_t total) {
        EXPECT_EQ(total, 20U);
        last_progress = done;
    };
    const SequenceDescriptors result =
        DescribeSequence(SourceWithBadScan(20, 7), HeightConfig(50), options);
    EXPECT_EQ(last_progress, 20U);
    ASSERT_EQ(result.skipped.size(), 1U);
    EXPECT_NE(result.skipped[0].find("scan 7:"), std::string::npos);
    EXPECT_EQ(result.database.size(), 20U);
    EXPECT_FALSE(result.database.IsValid(7));
    EXPECT_DOUBLE_EQ(result.database.TimeS(19), 1.9);
    EXPECT_EQ(result.database.Distance(7, 3), std::numeric_limits<double>::infinity());
    LoopDetector detector(result.database, Deciding(DetectorConfig{}, 1.0));
    const LoopQuery q =
        detector.Query(ComputeDescriptor(test::RandomCloud(500, 7), HeightConfig(50)));
    ASSERT_TRUE(q.has_match());
    EXPECT_NE(q.candidates.front().index, 7U);
}

TEST(DescribeSequence, ParallelEqualsSerial) {
    DescribeOptions serial;
    serial.execution = Execution::kSerial;
    ScanSource source = SourceWithBadScan(30, 1000);
    const auto a = DescribeSequence(source, HeightConfig(64), serial);
    const auto b = DescribeSequence(source, HeightConfig(64));
    EXPECT_EQ(HistogramRows(a.database)->data(), HistogramRows(b.database)->data());
}

}  // namespace
}  // namespace lidarloop::pipeline
