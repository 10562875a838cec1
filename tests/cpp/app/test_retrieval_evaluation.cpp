// evaluate's ranked-candidate figures recounted by hand from detect's verified candidates and the
// poses: the same candidates, verdicts and ground truth must give the same numbers.
#include <algorithm>
#include <cmath>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app_test_utils.hpp"
#include "lidarloop/app/detection.hpp"
#include "lidarloop/app/evaluation.hpp"
#include "test_utils.hpp"

namespace lidarloop {
namespace {

constexpr double kDistanceM = 10.0;
constexpr std::size_t kGapScans = 10;

struct Recount {
    std::size_t revisiting = 0, hits_at_1 = 0, hits_at_k = 0;
    std::size_t true_loops = 0, false_loops = 0, wrong_pose = 0;
};

bool SamePlace(const io::Dataset& dataset, std::size_t a, std::size_t b) {
    const auto& poses = dataset.poses();
    return (poses[a].T_world_sensor.translation() - poses[b].T_world_sensor.translation()).norm() <
           kDistanceM;
}

// Whether query q's first candidate, and any of them, is at its place.
void CountHits(const io::Dataset& dataset, const pipeline::LoopQuery& q, Recount& r) {
    r.hits_at_1 += SamePlace(dataset, q.query, q.candidates.front().index) ? 1 : 0;
    bool hit = false;
    for (const auto& c : q.candidates) hit = hit || SamePlace(dataset, q.query, c.index);
    r.hits_at_k += hit ? 1 : 0;
}

// Brute force over the poses: a scan revisits when an earlier scan more than the gap back is
// within the distance; a loop is the first accepted candidate.
Recount RecountFrom(const io::Dataset& dataset, const std::vector<pipeline::LoopQuery>& queries,
                    bool verified) {
    Recount r;
    for (std::size_t i = 0; i < dataset.size(); ++i) {
        for (std::size_t j = 0; j + kGapScans < i; ++j) {
            if (SamePlace(dataset, i, j)) {
                ++r.revisiting;
                break;
            }
        }
    }
    for (const pipeline::LoopQuery& q : queries) {
        if (!q.has_match()) continue;
        CountHits(dataset, q, r);
        const std::optional<std::size_t> loop = q.loop();
        if (!loop) continue;
        const std::size_t match = q.candidates[*loop].index;
        (SamePlace(dataset, q.query, match) ? r.true_loops : r.false_loops)++;
        if (!verified) continue;
        const core::Transform truth = dataset.poses()[match].T_world_sensor.inverse() *
                                      dataset.poses()[q.query].T_world_sensor;
        const core::Transform error = truth.inverse() * q.verifications[*loop].T_match_query;
        const bool wrong = error.translation().norm() > 1.0 ||
                           Eigen::AngleAxisd(error.linear()).angle() * 180.0 / M_PI > 2.0;
        r.wrong_pose += wrong ? 1 : 0;
    }
    return r;
}

// The same, each candidate decided by the descriptor's threshold (range: distance <= tau): a
// query's loop is its first candidate that passes.
Recount RecountByThreshold(const io::Dataset& dataset,
                           const std::vector<pipeline::LoopQuery>& queries, double tau) {
    Recount r = RecountFrom(dataset, {}, false);  // the revisiting scans
    for (const pipeline::LoopQuery& q : queries) {
        if (!q.has_match()) continue;
        CountHits(dataset, q, r);
        const auto loop = std::find_if(q.candidates.begin(), q.candidates.end(),
                                       [&](const auto& c) { return c.distance <= tau; });
        if (loop == q.candidates.end()) continue;
        (SamePlace(dataset, q.query, loop->index) ? r.true_loops : r.false_loops)++;
    }
    return r;
}

void ExpectSame(const Recount& r, const eval::LoopRetrievalEvaluation& e, std::size_t scans) {
    EXPECT_EQ(e.revisiting, r.revisiting);
    EXPECT_EQ(e.hits_at_1, r.hits_at_1);
    EXPECT_EQ(e.hits_at_k, r.hits_at_k);
    EXPECT_EQ(e.true_loops, r.true_loops);
    EXPECT_EQ(e.false_loops, r.false_loops);
    EXPECT_DOUBLE_EQ(e.recall,
                     static_cast<double>(r.true_loops) / static_cast<double>(r.revisiting));
    EXPECT_EQ(e.scans, scans);
}

TEST(RetrievalEvaluation, EvaluateRecountsFromDetectsCandidates) {
    const test::TempDir dir;
    const io::Dataset dataset = test::SmallSequence(dir / "sequence");
    io::RunConfig config;
    config.descriptor.method = core::Method::kRange;
    config.detection.min_gap.value = static_cast<double>(kGapScans);
    // Two verified runs: under the sanitizers one candidate a scan (a minute less), else two.
    config.detection.top_k = test::kSanitizedBuild ? 1 : 2;
    // Scans alone: the recount does not depend on how they were prepared, and submaps placed by
    // the neighbours made the sanitized test take two minutes.
    config.detection.verification.reduction.submap_path_m = 0.0;

    app::EvaluationRequest request;
    request.methods = {core::Method::kRange};
    request.config = config;
    request.distance_m = kDistanceM;
    request.out = dir / "evaluation";
    const app::EvaluationOutcome evaluated = app::RunEvaluation(dataset, request);
    ASSERT_EQ(evaluated.methods.size(), 1U);
    ASSERT_TRUE(evaluated.methods[0].retrieval.has_value());
    const app::RetrievalComparison& r = *evaluated.methods[0].retrieval;
    ASSERT_TRUE(r.verified.has_value());

    app::DetectRequest detect{config, false, {}, dir / "detection", {}, {}, {}};
    const app::DetectOutcome detected = app::RunDetect(dataset, detect);
    const Recount verified = RecountFrom(dataset, detected.queries, true);
    ExpectSame(verified, *r.verified, dataset.size());
    EXPECT_EQ(r.verified->wrong_pose_loops, verified.wrong_pose);
    EXPECT_GT(verified.true_loops, 10U);  // the sequence revisits: the test has something to count

    // The descriptor's figures are of the same ranking (the order registration uses: the layouts'
    // without odometry), each candidate decided by the threshold alone.
    ExpectSame(RecountByThreshold(dataset, detected.queries,
                                  config.detection.ThresholdFor(core::Method::kRange)),
               r.descriptor, dataset.size());

    std::ifstream file(dir / "evaluation" / "metrics.json");
    const nlohmann::json metrics = nlohmann::json::parse(file)["methods"]["range"]["retrieval"];
    EXPECT_EQ(metrics["k"], config.detection.top_k);
    EXPECT_EQ(metrics["verified"]["true_loops"], verified.true_loops);
    EXPECT_EQ(metrics["verified"]["wrong_pose_loops"], verified.wrong_pose);
    EXPECT_EQ(metrics["descriptor"]["revisiting_scans"], verified.revisiting);
}

// RecountFrom's rules with --min-path: a revisit needs more than `min_path_m` of path back too; a
// loop to the same place with less path is neither true nor false.
Recount RecountWithPath(const io::Dataset& dataset, const std::vector<pipeline::LoopQuery>& queries,
                        double min_path_m) {
    const auto revisit = [&](std::size_t a, std::size_t b) {
        return SamePlace(dataset, a, b) && test::BrutePathM(dataset.poses(), a, b) > min_path_m;
    };
    Recount r;
    for (std::size_t i = 0; i < dataset.size(); ++i) {
        for (std::size_t j = 0; j + kGapScans < i; ++j) {
            if (revisit(i, j)) {
                ++r.revisiting;
                break;
            }
        }
    }
    for (const pipeline::LoopQuery& q : queries) {
        if (!q.has_match()) continue;
        r.hits_at_1 += revisit(q.query, q.candidates.front().index) ? 1 : 0;
        bool hit = false;
        for (const auto& c : q.candidates) hit = hit || revisit(q.query, c.index);
        r.hits_at_k += hit ? 1 : 0;
        const std::optional<std::size_t> loop = q.loop();
        if (!loop) continue;
        const std::size_t match = q.candidates[*loop].index;
        if (revisit(q.query, match)) {
            ++r.true_loops;
        } else if (!SamePlace(dataset, q.query, match)) {
            ++r.false_loops;
        }
    }
    return r;
}

TEST(RetrievalEvaluation, MinPathCountsOnlyRevisitsFarBackInPath) {
    const test::TempDir dir;
    const io::Dataset dataset = test::SmallSequence(dir / "sequence");
    app::EvaluationRequest request;
    request.methods = {core::Method::kRange};
    request.config.descriptor.method = core::Method::kRange;
    request.config.detection.min_gap.value = static_cast<double>(kGapScans);
    request.config.detection.top_k = 3;
    request.config.detection.verify = false;
    request.config.detection.threshold = 0.02;  // loose: loops to the recent past too
    request.distance_m = kDistanceM;
    // The median over revisiting scans of the longest path back to the same place: about half
    // of the revisits are then too little path back.
    std::vector<double> longest_back_m;
    for (std::size_t i = 0; i < dataset.size(); ++i) {
        double longest_m = 0.0;
        for (std::size_t j = 0; j + kGapScans < i; ++j) {
            if (SamePlace(dataset, i, j))
                longest_m = std::max(longest_m, test::BrutePathM(dataset.poses(), i, j));
        }
        if (longest_m > 0.0) longest_back_m.push_back(longest_m);
    }
    ASSERT_FALSE(longest_back_m.empty());
    std::sort(longest_back_m.begin(), longest_back_m.end());
    request.config.detection.min_path_m = longest_back_m[longest_back_m.size() / 2];
    request.out = dir / "evaluation";
    const app::EvaluationOutcome evaluated = app::RunEvaluation(dataset, request);
    const app::RetrievalComparison& r = *evaluated.methods.at(0).retrieval;
    const Recount expected =
        RecountWithPath(dataset, r.queries, request.config.detection.min_path_m);
    ExpectSame(expected, r.descriptor, dataset.size());
    // The candidates obey the rule, which bites: without it more scans revisit, and some
    // candidates are to the recent past.
    const double min_path_m = request.config.detection.min_path_m;
    const auto path_back = [&](const pipeline::LoopQuery& q, const pipeline::Neighbor& c) {
        return test::BrutePathM(dataset.poses(), q.query, c.index);
    };
    for (const pipeline::LoopQuery& q : r.queries) {
        for (const auto& c : q.candidates) EXPECT_GT(path_back(q, c), min_path_m);
    }
    EXPECT_GT(RecountWithPath(dataset, r.queries, 0.0).revisiting, expected.revisiting);
    request.config.detection.min_path_m = 0.0;
    request.out = dir / "no_path_rule";
    const app::EvaluationOutcome no_rule = app::RunEvaluation(dataset, request);
    std::size_t recent = 0;
    for (const pipeline::LoopQuery& q : no_rule.methods.at(0).retrieval->queries) {
        for (const auto& c : q.candidates) recent += path_back(q, c) > min_path_m ? 0 : 1;
    }
    EXPECT_GT(recent, 0u);
    request.config.detection.min_path_m = min_path_m;
    EXPECT_GT(expected.revisiting, 0u);
    EXPECT_EQ(evaluated.truth.OverlappingCount(), [&] {
        std::size_t overlapping = 0;  // either direction, outside the gap
        for (std::size_t i = 0; i < dataset.size(); ++i) {
            bool any = false;
            for (std::size_t j = 0; j < dataset.size() && !any; ++j) {
                const std::size_t apart = i > j ? i - j : j - i;
                any = apart > kGapScans && SamePlace(dataset, i, j) &&
                      test::BrutePathM(dataset.poses(), i, j) > request.config.detection.min_path_m;
            }
            overlapping += any ? 1 : 0;
        }
        return overlapping;
    }());
}

}  // namespace
}  // namespace lidarloop
