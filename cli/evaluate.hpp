#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "evaluation_run.hpp"
#include "lidarloop/io/config_yaml.hpp"
#include "lidarloop/io/dataset.hpp"

namespace lidarloop::cli {

/// What `lidarloop evaluate` (and `lidarloop demo`) asks for.
struct EvaluationRequest {
    io::RunConfig config;  ///< descriptors, and detection.min_gap as the evaluation's gap S
    std::vector<core::Method> methods;
    std::vector<std::string> results_files;  ///< other detectors' query,match,distance CSVs
    double distance_m = 10.0;                ///< same place when closer (Röhling d, Magnusson t_r)
    double max_heading_deg = 0.0;            ///< and headings closer than this; 0: any
    eval::ThresholdLearningConfig learning;
    std::vector<double> fixed_thresholds;  ///< MCC at each, as Röhling's table II
    bool skip_bad = false;
    bool quiet = false;
    std::filesystem::path out;
};

struct EvaluationOutcome {
    eval::GroundTruth truth;
    std::vector<MethodEvaluation> methods;
    std::vector<std::string> notes;  ///< figures that could not be drawn
};

/// Evaluates every method and results file on one ground truth from the dataset's poses and
/// writes metrics.json, roc.csv, pr.csv, the images and figures and report.md into request.out.
/// With `train_dataset` (which needs poses too), each method's threshold is learnt on all its
/// pairs under the same ground-truth rule and tested on all pairs of `dataset`; results files
/// keep learning on the first part.
EvaluationOutcome RunEvaluation(const io::Dataset& dataset, const EvaluationRequest& request,
                                const io::Dataset* train_dataset = nullptr);

}  // namespace lidarloop::cli
