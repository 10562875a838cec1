#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "lidarloop/app/progress.hpp"
#include "lidarloop/io/config_yaml.hpp"
#include "lidarloop/io/dataset.hpp"

namespace lidarloop::app {

/// What `lidarloop bench` asks for.
struct BenchRequest {
    io::RunConfig config;
    std::size_t queries = 200;  ///< query scans to time
    std::size_t scale_to = 0;   ///< also time queries against this many histograms (synthetic)
    /// Query scans whose top-k candidates (config.detection.top_k) are verified on one core, to
    /// time verification per pair; 0: verification is not timed.
    std::size_t verify_queries = 50;
    /// The scans' odometry (a file, or a topic of the dataset's bag), as `detect --odometry`
    /// takes it: the timed queries then shortlist, register and gate with it (reach, view order,
    /// the odometry gate), as the online detector with a gate does; empty: none.
    std::filesystem::path odometry_file;
    std::string odometry_topic;
    std::filesystem::path odometry_calib;  ///< as DetectRequest::odometry_calib
    /// The similarity matrix is timed on at most this many scans, the first (2..kMaxMatrixScans):
    /// a comparison costs the same whatever the length, but the matrix grows with its square.
    std::size_t matrix_scans = 4000;
    Progress progress;

    /// Throws core::ConfigError for counts no machine holds (queries, verify_queries over
    /// kMaxQueries; matrix_scans over kMaxMatrixScans; scale_to over kMaxScaleTo histograms,
    /// gigabytes), for a matrix of fewer than 2 scans, and for scale_to with a method that has no
    /// histogram index (it would be ignored).
    void Validate() const;
    static constexpr std::size_t kMaxQueries = 1'000'000;
    static constexpr std::size_t kMaxScaleTo = 2'000'000;
    static constexpr std::size_t kMaxMatrixScans = 50'000;  ///< a matrix of 5 GB
};

/// Times describing (one core), the similarity matrix of the first matrix_scans scans (one core
/// and all cores), and top-1 queries through the index and by brute force on `dataset`; with
/// scale_to, also queries against a synthetic database of that many perturbed histograms; and
/// geometric verification on one core: preparing a scan, the query's coarse images, and each
/// candidate pair (wall and thread CPU time), with the bytes kept per prepared scan (with the
/// odometry as detect uses it, when given). The figures as JSON (keys in docs/cli.md), with the
/// peak memory of the process.
nlohmann::json RunBench(const io::Dataset& dataset, const BenchRequest& request);

}  // namespace lidarloop::app
