#include "lidarloop/app/results_folder.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>

#include "lidarloop/eval/summary.hpp"
#include "lidarloop/io/read_error.hpp"

namespace lidarloop::app {

std::filesystem::path PrepareOutputFolder(const std::filesystem::path& folder) {
    std::error_code ec;
    std::filesystem::create_directories(folder, ec);
    if (ec || !std::filesystem::is_directory(folder)) {
        throw io::WriteError(folder, "cannot create the output folder" +
                                         (ec ? " (" + ec.message() + ")" : std::string()));
    }
    return folder;
}

double Quantile(std::vector<double> values, double q) {
    if (values.empty()) return 0.0;
    std::sort(values.begin(), values.end());
    return eval::Quantile(values, q);
}

nlohmann::json SummaryJson(const std::vector<double>& values, double scale) {
    return {{"median", scale * Quantile(values, 0.5)},
            {"p95", scale * Quantile(values, 0.95)},
            {"max", scale * Quantile(values, 1.0)}};
}

void WriteJson(const std::filesystem::path& file, const nlohmann::json& json) {
    std::ofstream out(file);
    out << json.dump(2) << "\n";
    if (!out) throw io::WriteError(file, "writing failed");
}

void WriteSkipped(const std::filesystem::path& folder, const std::vector<std::string>& skipped) {
    if (skipped.empty()) return;
    std::ofstream out(folder / "skipped.txt");
    for (const std::string& line : skipped) out << line << "\n";
    if (!out) throw io::WriteError(folder / "skipped.txt", "writing failed");
}

void WriteLoopsCsv(const std::filesystem::path& file,
                   const std::vector<pipeline::LoopQuery>& queries) {
    std::ofstream out(file);
    out << "query,match,distance,second_ratio,accepted\n";
    out.precision(9);
    for (const auto& q : queries) {
        if (!q.has_match()) continue;
        out << q.query << ',' << q.candidates.front().index << ',' << q.candidates.front().distance
            << ',';
        if (!std::isnan(q.second_ratio)) out << q.second_ratio;
        out << ',' << (q.accepted ? 1 : 0) << '\n';
    }
    if (!out) throw io::WriteError(file, "writing failed");
}

void WriteCandidatesCsv(const std::filesystem::path& file,
                        const std::vector<pipeline::LoopQuery>& queries) {
    std::ofstream out(file);
    out << "query,rank,match,distance\n";
    out.precision(9);
    for (const auto& q : queries) {
        for (std::size_t r = 0; r < q.candidates.size(); ++r) {
            out << q.query << ',' << r + 1 << ',' << q.candidates[r].index << ','
                << q.candidates[r].distance << '\n';
        }
    }
    if (!out) throw io::WriteError(file, "writing failed");
}

std::size_t CountAccepted(const std::vector<pipeline::LoopQuery>& queries) {
    std::size_t accepted = 0;
    for (const auto& q : queries) accepted += q.accepted ? 1 : 0;
    return accepted;
}

}  // namespace lidarloop::app
