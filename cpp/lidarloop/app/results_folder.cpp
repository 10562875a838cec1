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
    // Nothing measured is no figure, not a zero.
    if (values.empty()) return {{"median", nullptr}, {"p95", nullptr}, {"max", nullptr}};
    return {{"median", scale * Quantile(values, 0.5)},
            {"p95", scale * Quantile(values, 0.95)},
            {"max", scale * Quantile(values, 1.0)}};
}

void WriteJson(const std::filesystem::path& file, const nlohmann::json& json) {
    std::ofstream out(file);
    out << json.dump(2) << "\n";
    out.close();  // flushes: a full disk fails here, not silently in the destructor
    if (!out) throw io::WriteError(file, "writing failed");
}

void WriteSkipped(const std::filesystem::path& folder, const std::vector<std::string>& skipped) {
    if (skipped.empty()) return;
    std::ofstream out(folder / "skipped.txt");
    for (const std::string& line : skipped) out << line << "\n";
    out.close();
    if (!out) throw io::WriteError(folder / "skipped.txt", "writing failed");
}

namespace {

bool AnyVerified(const std::vector<pipeline::LoopQuery>& queries) {
    return std::any_of(queries.begin(), queries.end(), [](const auto& q) { return q.verified(); });
}

constexpr char kVerificationColumns[] =
    "tx,ty,tz,qx,qy,qz,qw,overlap_query,overlap_match,distinctive_query,distinctive_match,rmse_m,"
    "shifted_overlap,reason";
// The empty verification fields of an unverified row in a verified file (14 columns), so that
// path_m stays under its header.
constexpr char kNoVerification[] = ",,,,,,,,,,,,,";

// Writes ",path_m": the path travelled between the two scans, or "," when it is unknown.
void WritePathM(std::ostream& out, const std::vector<double>& path_m, std::size_t query,
                std::size_t match) {
    out << ',';
    if (query < path_m.size() && match < path_m.size())
        out << std::abs(path_m[query] - path_m[match]);
}

// The verification columns of one candidate: T_match_query (translation in metres, unit
// quaternion x, y, z, w), the overlap both ways, the RMSE, the degeneracy test's overlap ratio
// (empty when not reached) and the reason ("none" when accepted).
// A candidate rejected before registration has empty pose and fit fields.
void WriteVerification(std::ostream& out, const registration::Verification& v) {
    if (v.Registered()) {
        const Eigen::Vector3d t = v.T_match_query.translation();
        const Eigen::Quaterniond q(v.T_match_query.rotation());
        out << t.x() << ',' << t.y() << ',' << t.z() << ',' << q.x() << ',' << q.y() << ',' << q.z()
            << ',' << q.w() << ',' << v.overlap.query_fraction << ',' << v.overlap.match_fraction
            << ',' << v.overlap.query_distinctive_fraction << ','
            << v.overlap.match_distinctive_fraction << ',' << v.overlap.rmse_m << ',';
        if (!std::isnan(v.shifted_overlap_ratio)) out << v.shifted_overlap_ratio;
        out << ',';
    } else {
        out << ",,,,,,,,,,,,,";
    }
    out << registration::ToString(v.reason);
}

}  // namespace

void WriteLoopsCsv(const std::filesystem::path& file,
                   const std::vector<pipeline::LoopQuery>& queries,
                   const std::vector<double>& path_m) {
    std::ofstream out(file);
    const bool verified = AnyVerified(queries);
    out << "query,match,distance,second_ratio,accepted";
    out << (verified ? std::string(",rank,") + kVerificationColumns : std::string()) << ",path_m\n";
    out.precision(9);
    for (const auto& q : queries) {
        if (!q.has_match()) continue;
        const std::size_t rank = q.loop().value_or(0);
        out << q.query << ',' << q.candidates[rank].index << ',' << q.candidates[rank].distance
            << ',';
        if (!std::isnan(q.second_ratio)) out << q.second_ratio;
        out << ',' << (q.accepted ? 1 : 0);
        if (q.verified()) {
            out << ',' << rank + 1 << ',';
            WriteVerification(out, q.verifications[rank]);
        } else if (verified) {
            out << ',' << ',' << kNoVerification;  // rank and the verification fields
        }
        WritePathM(out, path_m, q.query, q.candidates[rank].index);
        out << '\n';
    }
    out.close();
    if (!out) throw io::WriteError(file, "writing failed");
}

void WriteCandidatesCsv(const std::filesystem::path& file,
                        const std::vector<pipeline::LoopQuery>& queries,
                        const std::vector<double>& path_m) {
    std::ofstream out(file);
    const bool verified = AnyVerified(queries);
    out << "query,rank,match,distance";
    out << (verified ? std::string(",accepted,") + kVerificationColumns : std::string())
        << ",path_m\n";
    out.precision(9);
    for (const auto& q : queries) {
        for (std::size_t r = 0; r < q.candidates.size(); ++r) {
            out << q.query << ',' << r + 1 << ',' << q.candidates[r].index << ','
                << q.candidates[r].distance;
            if (q.verified()) {
                out << ',' << (q.verifications[r].accepted ? 1 : 0) << ',';
                WriteVerification(out, q.verifications[r]);
            } else if (verified) {
                out << ',' << ',' << kNoVerification;  // accepted and the verification fields
            }
            WritePathM(out, path_m, q.query, q.candidates[r].index);
            out << '\n';
        }
    }
    out.close();
    if (!out) throw io::WriteError(file, "writing failed");
}

std::size_t CountAccepted(const std::vector<pipeline::LoopQuery>& queries) {
    std::size_t accepted = 0;
    for (const auto& q : queries) accepted += q.accepted ? 1 : 0;
    return accepted;
}

std::size_t CountRejected(const std::vector<pipeline::LoopQuery>& queries,
                          registration::RejectReason reason) {
    std::size_t rejected = 0;
    for (const auto& q : queries) {
        for (const auto& v : q.verifications) rejected += v.reason == reason ? 1 : 0;
    }
    return rejected;
}

}  // namespace lidarloop::app
