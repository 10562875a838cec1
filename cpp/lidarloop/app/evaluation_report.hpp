#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "lidarloop/app/evaluation.hpp"

namespace lidarloop::app {

/// What the report says about the run besides the methods.
struct ReportContext {
    std::string dataset;
    std::size_t scans = 0;
    std::string ground_truth_rule;
};

/// roc.csv and pr.csv: the curves of every method, one row per curve point.
void WriteCurveCsvs(const std::filesystem::path& folder,
                    const std::vector<MethodEvaluation>& evaluations);

/// ground_truth.png, similarity_<method>.png (at the best-MCC threshold), and with gnuplot
/// roc.png, pr.png, em_<method>.png, counts_<method>.png. Returns the notes for figures that
/// could not be drawn (e.g. gnuplot missing).
std::vector<std::string> WriteFigures(const std::filesystem::path& folder,
                                      const eval::GroundTruth& truth,
                                      const std::vector<MethodEvaluation>& evaluations);

/// report.md: the tables of both papers for every method, then the figures side by side.
void WriteReport(const std::filesystem::path& folder, const ReportContext& context,
                 const std::vector<MethodEvaluation>& evaluations,
                 const std::vector<std::string>& notes);

}  // namespace lidarloop::app
