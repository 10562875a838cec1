#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "lidarloop/app/evaluation.hpp"

namespace lidarloop::app {

/// metrics.json's entry for one method (keys in docs/cli.md).
nlohmann::json MetricsJson(const MethodEvaluation& evaluation);

/// The whole metrics.json of an evaluation: dataset, scans, ground-truth rule, every method.
nlohmann::json EvaluationMetricsJson(const std::string& dataset, std::size_t scans,
                                     const EvaluationOutcome& outcome);

}  // namespace lidarloop::app
