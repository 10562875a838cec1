#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lidarloop/core/stopwatch.hpp"
#include "lidarloop/pipeline/loop_detector.hpp"

namespace lidarloop::app {

/// Creates `folder` (and parents); io::WriteError when that is impossible.
std::filesystem::path PrepareOutputFolder(const std::filesystem::path& folder);

// The clocks of the run's timings (core/stopwatch.hpp).
using core::Stopwatch;
using core::ThreadCpuStopwatch;

/// The q-quantile (0..1) of `values` (eval::Quantile after sorting); 0 for an empty list.
double Quantile(std::vector<double> values, double q);

/// {median, p95, max} of `values` times `scale`; all three null for an empty list (nothing
/// measured is no figure).
nlohmann::json SummaryJson(const std::vector<double>& values, double scale = 1.0);

void WriteJson(const std::filesystem::path& file, const nlohmann::json& json);
/// Writes skipped.txt (one line per skipped scan) when any scan was skipped.
void WriteSkipped(const std::filesystem::path& folder, const std::vector<std::string>& skipped);

/// loops.csv: one row per query scan with a candidate, its best match
/// (query,match,distance,second_ratio,accepted). Verified queries: the match is the loop (the
/// first accepted candidate, else the best one), then its rank and verification columns
/// (rank,tx,ty,tz,qx,qy,qz,qw,overlap_query,overlap_match,distinctive_query,distinctive_match,rmse_m,
/// shifted_overlap,reason;
/// docs/cli.md), and last path_m: the path travelled between query and match, metres, from
/// `path_m` (per scan, core::CumulativePathM); empty when `path_m` is empty. In a verified file an
/// unverified row has empty verification fields, so every row has the header's columns.
void WriteLoopsCsv(const std::filesystem::path& file,
                   const std::vector<pipeline::LoopQuery>& queries,
                   const std::vector<double>& path_m = {});
/// candidates.csv: every candidate of every query (query,rank,match,distance), and when verified
/// accepted and the verification columns of loops.csv; last path_m as in loops.csv.
void WriteCandidatesCsv(const std::filesystem::path& file,
                        const std::vector<pipeline::LoopQuery>& queries,
                        const std::vector<double>& path_m = {});

/// Query scans with an accepted loop.
std::size_t CountAccepted(const std::vector<pipeline::LoopQuery>& queries);

/// Candidates of `queries` rejected for `reason`.
std::size_t CountRejected(const std::vector<pipeline::LoopQuery>& queries,
                          registration::RejectReason reason);

}  // namespace lidarloop::app
