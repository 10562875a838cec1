#include "lidarloop/eval/threshold_learning.hpp"

#include <array>
#include <cmath>

#include "lidarloop/core/enum_names.hpp"
#include "lidarloop/core/error.hpp"

namespace lidarloop::eval {

namespace {

constexpr auto kCriterionNames = std::to_array<core::EnumName<Criterion>>({
    {Criterion::kMcc, "mcc"},
    {Criterion::kF1, "f1"},
});
static_assert(core::IsOneToOne(kCriterionNames));

}  // namespace

std::string ToString(Criterion criterion) {
    return std::string(core::NameOf(kCriterionNames, criterion));
}

Criterion ParseCriterion(std::string_view name) {
    return core::ParseEnum(kCriterionNames, name, "threshold criterion");
}

ThresholdTransfer LearnAndTest(std::span<const ScoredPair> train, std::span<const ScoredPair> test,
                               Criterion criterion) {
    if (train.empty()) throw core::EmptyInputError("threshold learning: no training pairs");
    if (test.empty()) throw core::EmptyInputError("threshold learning: no test pairs");
    // Only the optimum is needed; the smallest curve keeps the sweep cheap.
    const PairwiseEvaluation learnt = EvaluatePairs(train, PairwiseConfig{3});
    // Without a finite training distance the optimum is "detect nothing" at -inf: no threshold
    // a detector could apply.
    if (learnt.distinct_thresholds == 0) {
        throw core::EmptyInputError("threshold learning: no training pair has a finite distance");
    }
    const BestThreshold& best = criterion == Criterion::kMcc ? learnt.best_mcc : learnt.best_f1;
    return TransferOf(criterion, best, ConfusionAt(test, best.threshold));
}

ThresholdTransfer TransferOf(Criterion criterion, const BestThreshold& learnt,
                             const Confusion& test) {
    ThresholdTransfer result;
    result.criterion = criterion;
    result.threshold = learnt.threshold;
    result.train_score = learnt.score;
    result.train = learnt.confusion;
    result.test = test;
    result.test_f1 = F1(test);
    result.test_mcc = Mcc(test);
    return result;
}

PairSplit SplitByQuery(std::span<const ScoredPair> pairs, std::size_t first_test_scan) {
    PairSplit split;
    split.first_test_scan = first_test_scan;
    for (const auto& pair : pairs) {
        (pair.j < first_test_scan ? split.train : split.test).push_back(pair);
    }
    return split;
}

void ThresholdLearningConfig::Validate() const {
    if (!(train_fraction > 0.0 && train_fraction < 1.0)) {
        throw core::ConfigError("threshold_learning.train_fraction must be in (0, 1), got " +
                                std::to_string(train_fraction));
    }
}

ThresholdTransfer LearnOnFirstPart(std::span<const ScoredPair> pairs, std::size_t scan_count,
                                   const ThresholdLearningConfig& config) {
    config.Validate();
    const auto first_test_scan = static_cast<std::size_t>(
        std::llround(config.train_fraction * static_cast<double>(scan_count)));
    const PairSplit split = SplitByQuery(pairs, first_test_scan);
    return LearnAndTest(split.train, split.test, config.criterion);
}

}  // namespace lidarloop::eval
