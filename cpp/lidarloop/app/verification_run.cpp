#include "lidarloop/app/verification_run.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include <tbb/parallel_for.h>

#include "lidarloop/app/results_folder.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/core/min_gap.hpp"
#include "lidarloop/io/scan_reader.hpp"
#include "lidarloop/pipeline/expanded_scans.hpp"
#include "lidarloop/posegraph/optimiser.hpp"
#include "lidarloop/registration/submap.hpp"

namespace lidarloop::app {

std::function<void(std::size_t, const core::PointCloud&)> PreparedScans::Collector(
    const registration::ScanReductionConfig& reduction) {
    return [this, &reduction](std::size_t i, const core::PointCloud& cloud) {
        const Stopwatch clock;
        const ThreadCpuStopwatch cpu_clock;
        scans.at(i) =
            registration::CompactPreparedScan(registration::PrepareScan(cloud, reduction));
        prepare_seconds.at(i) = clock.Seconds();
        prepare_cpu_seconds.at(i) = cpu_clock.Seconds();
        readable.at(i) = 1;
    };
}

std::function<void(std::size_t, const core::PointCloud&)> PreparedScans::ReadMarker() {
    return [this](std::size_t i, const core::PointCloud&) { readable.at(i) = 1; };
}

std::function<void(std::size_t, const core::PointCloud&)> PreparedScans::CollectorFor(
    const registration::ScanReductionConfig& reduction) {
    return reduction.submap_path_m > 0.0 ? ReadMarker() : Collector(reduction);
}

std::vector<double> PreparedScans::BytesPerScan() const {
    std::vector<double> bytes;
    for (const auto& scan : scans) {
        if (scan.prepared()) bytes.push_back(static_cast<double>(scan.MemoryBytes()));
    }
    return bytes;
}

namespace {

// Centres per block of PrepareSubmapsInOrder: enough to keep both cores busy between reads,
// few enough that a block's scans (at most this plus two windows of submap_max_scans) fit in
// memory even for dense scans.
constexpr std::size_t kSubmapBlock = 32;

// The scans the submaps of `centres` need, each once, in sequence order.
std::vector<std::size_t> BlockMembers(const std::vector<double>& path_m,
                                      const std::vector<std::size_t>& centres,
                                      const registration::SubmapWindow& window) {
    std::vector<std::size_t> members;
    for (const std::size_t centre : centres) {
        for (const std::size_t k : registration::SubmapMembers(path_m, centre, window))
            members.push_back(k);
    }
    std::sort(members.begin(), members.end());
    members.erase(std::unique(members.begin(), members.end()), members.end());
    return members;
}

}  // namespace

void PrepareSubmapsInOrder(const std::vector<core::StampedPose>& poses,
                           const registration::ScanReductionConfig& reduction,
                           const std::function<core::PointCloud(std::size_t)>& load,
                           const std::function<bool(std::size_t)>& wanted, const SubmapSink& take) {
    const std::vector<double> path_m = registration::SubmapPathM(poses);
    const registration::SubmapWindow window{reduction.submap_path_m, reduction.submap_max_scans,
                                            false};
    std::map<std::size_t, core::PointCloud> loaded;  // the scans the current block needs
    for (std::size_t start = 0; start < poses.size(); start += kSubmapBlock) {
        std::vector<std::size_t> centres;
        for (std::size_t i = start; i < std::min(start + kSubmapBlock, poses.size()); ++i) {
            if (wanted(i)) centres.push_back(i);
        }
        if (centres.empty()) continue;
        const std::vector<std::size_t> members = BlockMembers(path_m, centres, window);
        // Scans no later block needs go; the window only moves forward along the path.
        loaded.erase(loaded.begin(), loaded.lower_bound(members.front()));
        std::vector<std::size_t> missing;
        for (const std::size_t k : members) {
            if (!loaded.contains(k)) missing.push_back(k);
        }
        const Stopwatch read_clock;
        std::vector<core::PointCloud> read(missing.size());
        tbb::parallel_for(std::size_t{0}, missing.size(),
                          [&](std::size_t m) { read[m] = load(missing[m]); });
        for (std::size_t m = 0; m < missing.size(); ++m) loaded[missing[m]] = std::move(read[m]);
        const double read_seconds_per_centre =
            read_clock.Seconds() / static_cast<double>(centres.size());
        const auto from_memory = [&loaded](std::size_t k) { return loaded.at(k); };
        tbb::parallel_for(std::size_t{0}, centres.size(), [&](std::size_t c) {
            const Stopwatch clock;
            registration::PreparedScan submap =
                registration::PrepareSubmap(centres[c], poses, path_m, from_memory, reduction);
            take(centres[c], std::move(submap), clock.Seconds() + read_seconds_per_centre);
        });
    }
}

void PrepareSubmaps(const io::Dataset& dataset, const std::vector<core::StampedPose>& poses,
                    const registration::ScanReductionConfig& reduction, PreparedScans& prepared,
                    const Progress& progress) {
    // A scan skipped while describing could not be read: it adds nothing to its neighbours.
    const std::vector<char>& readable = prepared.readable;
    const auto load = [&](std::size_t k) {
        return readable.at(k) != 0 ? dataset.LoadScan(k) : core::PointCloud{};
    };
    const auto wanted = [&readable](std::size_t i) { return readable.at(i) != 0; };
    const auto total = static_cast<std::size_t>(
        std::count_if(readable.begin(), readable.end(), [](char r) { return r != 0; }));
    pipeline::ProgressCounter done(StageReport(progress, "submaps"), total);
    PrepareSubmapsInOrder(poses, reduction, load, wanted,
                          [&](std::size_t i, registration::PreparedScan submap, double seconds) {
                              prepared.scans[i] = registration::CompactPreparedScan(submap);
                              prepared.prepare_seconds[i] += seconds;
                              done.Add();
                          });
}

void PrepareSubmapsFromNeighbours(const io::Dataset& dataset,
                                  const registration::VerificationConfig& verification,
                                  PreparedScans& prepared, const Progress& progress) {
    const std::size_t count = prepared.scans.size();
    // The scans alone serve the registrations only; once each pair is registered the rules
    // read the cached results, and the scans alone are freed before any submap is made.
    auto alone = std::make_shared<std::vector<registration::CompactPreparedScan>>(
        std::exchange(prepared.scans, std::vector<registration::CompactPreparedScan>(count)));
    auto expanded = std::make_shared<pipeline::ExpandedScans>();
    prepared.neighbours = std::make_shared<pipeline::NeighbourOverlaps>(
        [alone, expanded](std::size_t i) { return expanded->Get(*alone, i); },
        [count] { return count; }, verification);
    const Stopwatch clock;
    const std::vector<core::StampedPose> poses = pipeline::PosesFromNeighbours(
        *prepared.neighbours, count, verification.reduction.submap_path_m,
        pipeline::Execution::kParallel);
    if (progress) progress("neighbours", count, count);
    prepared.submaps_apart = pipeline::SubmapsApart(poses, verification.reduction.submap_path_m);
    alone->clear();
    alone->shrink_to_fit();
    // Each scan's share of the registrations counts in its preparation.
    const double share_s = clock.Seconds() / static_cast<double>(std::max<std::size_t>(count, 1));
    for (double& seconds : prepared.prepare_seconds) seconds += share_s;
    PrepareSubmaps(dataset, poses, verification.reduction, prepared, progress);
}

void PrepareSubmapsIfAsked(const io::Dataset& dataset,
                           const std::vector<core::StampedPose>& odometry,
                           const registration::VerificationConfig& verification,
                           PreparedScans& prepared, const Progress& progress) {
    if (verification.reduction.submap_path_m <= 0.0) return;
    if (odometry.empty()) {
        PrepareSubmapsFromNeighbours(dataset, verification, prepared, progress);
    } else {
        PrepareSubmaps(dataset, odometry, verification.reduction, prepared, progress);
    }
}

bool NeighboursPlaceSubmaps(const io::Dataset& dataset,
                            const std::vector<core::StampedPose>& odometry) {
    return odometry.empty() && !core::KnowsDrivePath(dataset.poses());
}

bool SubmapsApply(const registration::ScanReductionConfig& reduction,
                  const std::vector<core::StampedPose>& poses, std::size_t scans, std::string& note,
                  bool neighbours_place) {
    if (reduction.submap_path_m <= 0.0 || reduction.submap_max_scans == 0) return false;
    if (poses.empty() && neighbours_place) {
        note =
            "submaps (verification.reduction.submap_path_m) placed by each scan's registration "
            "to the one before, as no odometry is given; a piece ends where that registration "
            "is not accepted";
        return true;
    }
    if (poses.size() != scans) {
        note =
            "no submaps (verification.reduction.submap_path_m): they need the scans' odometry; "
            "give --odometry FILE (or --odometry-topic) to register against a scan and its "
            "neighbours (a dataset's own poses are taken as its ground truth)";
        return false;
    }
    return true;
}

io::RunConfig WithSubmapsWhereTheyApply(const io::RunConfig& config, const io::Dataset& dataset,
                                        const std::vector<core::StampedPose>& poses,
                                        std::vector<std::string>& notes, bool neighbours_place,
                                        bool alone_when_dense) {
    io::RunConfig effective = config;
    std::string note;
    auto& reduction = effective.detection.verification.reduction;
    if (!effective.detection.verify) return effective;
    if (!SubmapsApply(reduction, poses, dataset.size(), note, neighbours_place)) {
        reduction.submap_path_m = 0.0;
    } else if (alone_when_dense && ScansFillTheStructureCap(dataset, reduction)) {
        reduction.submap_path_m = 0.0;
        note =
            "no submaps (verification.reduction.submap_path_m): the typical scan fills the "
            "structure cap alone (verification.reduction.max_structure_points), so its "
            "neighbours would add cost, not density; each scan is verified alone";
    }
    if (!note.empty()) notes.push_back(note);
    return effective;
}

namespace {

// Scans prepared to judge a sequence's density: enough for a stable median, few enough to cost
// less than one submap of dense scans.
constexpr std::size_t kDensitySample = 15;

}  // namespace

bool ScansFillTheStructureCap(const io::Dataset& dataset,
                              const registration::ScanReductionConfig& reduction) {
    const std::size_t count = dataset.size();
    const std::size_t sample = std::min(count, kDensitySample);
    constexpr std::size_t kUnread = std::numeric_limits<std::size_t>::max();
    std::vector<std::size_t> structure(sample, kUnread);
    tbb::parallel_for(std::size_t{0}, sample, [&](std::size_t i) {
        const std::size_t scan = (2 * i + 1) * count / (2 * sample);  // the middle of each share
        try {
            const registration::PreparedScan alone =
                registration::PrepareScan(dataset.LoadScan(scan), reduction);
            structure[i] = alone.structure ? alone.structure->size() : 0;
        } catch (const core::ConfigError&) {
            throw;  // a bad configuration is not a bad scan
        } catch (const core::Error&) {
            // Unreadable: describing the sequence reports it (or skips it with --skip-bad).
        }
    });
    std::erase(structure, kUnread);
    if (structure.empty()) return false;
    const auto median = structure.begin() + static_cast<std::ptrdiff_t>(structure.size() / 2);
    std::nth_element(structure.begin(), median, structure.end());
    return *median >= static_cast<std::size_t>(reduction.max_structure_points);
}

pipeline::VerificationTimes VerifyAll(std::vector<pipeline::LoopQuery>& queries,
                                      const PreparedScans& prepared,
                                      const pipeline::DetectorConfig& detector,
                                      const core::Method& method, const Progress& progress,
                                      pipeline::VerificationCache* cache,
                                      const pipeline::LoopCheck& check,
                                      const pipeline::MoreLoopsWanted& more) {
    return pipeline::VerifyQueries(
        queries, prepared.scans, detector, method, pipeline::Execution::kParallel,
        StageReport(progress, "verifying"), cache, check, more, prepared.neighbours.get());
}

pipeline::OdometryGate OdometryGateOf(const posegraph::PoseGraphConfig& config) {
    pipeline::OdometryGate gate;
    gate.rejects = [config](const core::Transform& T_match_query_loop,
                            const core::Transform& T_match_query_odometry, double path_m) {
        return posegraph::GateAgainstOdometry(T_match_query_loop, T_match_query_odometry, path_m,
                                              config)
                   .verdict == posegraph::LoopVerdict::kRejectedByOdometry;
    };
    gate.translation_allowance_m = [config](double path_m) {
        return posegraph::GateTranslationM(path_m, config);
    };
    gate.rotation_allowance_deg = [config](double path_m) {
        return posegraph::GateRotationDeg(path_m, config);
    };
    return gate;
}

pipeline::LoopCheck OdometryLoopCheck(const std::vector<core::StampedPose>& odometry,
                                      const std::vector<double>& path_m,
                                      const posegraph::PoseGraphConfig& config,
                                      std::atomic<std::size_t>* rejected,
                                      const PreparedScans* prepared) {
    const auto require_pose = [&odometry, &path_m](std::size_t scan) {
        if (scan >= odometry.size() || scan >= path_m.size()) {
            throw core::ConfigError("scan " + std::to_string(scan) + " has no odometry (" +
                                    std::to_string(odometry.size()) + " poses)");
        }
    };
    const auto pose_of = [&odometry, require_pose](std::size_t scan) {
        require_pose(scan);
        return odometry[scan].T_world_sensor;
    };
    const auto path_of = [&path_m, require_pose](std::size_t scan) {
        require_pose(scan);
        return path_m[scan];
    };
    std::function<Eigen::Vector3d(std::size_t)> view_centre_of;
    if (prepared != nullptr) {
        view_centre_of = [prepared](std::size_t scan) {
            return prepared->scans.at(scan).view_centre();
        };
    }
    return pipeline::CheckAgainstOdometry(pose_of, path_of, OdometryGateOf(config), rejected,
                                          view_centre_of);
}

pipeline::LoopCheck ScansOwnCheck(const PreparedScans& prepared,
                                  const registration::CoarseConfig& coarse) {
    pipeline::LoopCheck check = prepared.submaps_apart;
    const pipeline::LoopCheck layouts = pipeline::LayoutOrderOf(prepared.scans, coarse);
    check.layout_similarity = layouts.layout_similarity;
    check.yaw_window = layouts.yaw_window;
    return check;
}

std::size_t RejectLoopsAgainstOdometry(std::vector<pipeline::LoopQuery>& queries,
                                       const std::vector<core::StampedPose>& odometry,
                                       const std::vector<double>& path_m,
                                       const posegraph::PoseGraphConfig& config) {
    std::atomic<std::size_t> rejected{0};
    const pipeline::LoopCheck check = OdometryLoopCheck(odometry, path_m, config, &rejected);
    for (pipeline::LoopQuery& query : queries) check(query);
    return rejected;
}

nlohmann::json VerificationTimingsJson(const PreparedScans& prepared,
                                       const pipeline::VerificationTimes& times) {
    const auto ms = [](const std::vector<double>& seconds) { return SummaryJson(seconds, 1e3); };
    nlohmann::json json;
    json["prepare_ms_per_scan"] = ms(prepared.prepare_seconds);
    json["bytes_per_prepared_scan"] = SummaryJson(prepared.BytesPerScan());
    json["coarse_images_ms_per_query"] = ms(times.query_seconds);
    json["verify_ms_per_pair"] = ms(times.pair_seconds);
    json["pairs_verified"] = times.pair_seconds.size();
    return json;
}

PairVerification VerifyClouds(const core::PointCloud& query, const core::PointCloud& match,
                              const registration::VerificationConfig& config) {
    config.Validate();
    PairVerification result;
    result.query_points = query.size();
    result.match_points = match.size();
    const Stopwatch prepare_clock;
    const registration::PreparedScan prepared_query =
        registration::PrepareScan(query, config.reduction);
    const registration::PreparedScan prepared_match =
        registration::PrepareScan(match, config.reduction);
    result.prepare_ms = 1e3 * prepare_clock.Seconds();
    const Stopwatch verify_clock;
    if (prepared_query.structure) {
        const registration::CoarseQuery coarse(*prepared_query.structure, config.coarse);
        result.verdict = registration::Verify(prepared_query, coarse, prepared_match, config);
    } else {
        result.verdict.reason = registration::RejectReason::kTooFewPoints;
    }
    result.verify_ms = 1e3 * verify_clock.Seconds();
    return result;
}

PairVerification VerifyScanFiles(const std::filesystem::path& query_file,
                                 const std::filesystem::path& match_file,
                                 const registration::VerificationConfig& config) {
    config.Validate();
    return VerifyClouds(io::ReadScan(query_file), io::ReadScan(match_file), config);
}

nlohmann::json VerificationJson(const registration::Verification& verdict) {
    const registration::Overlap& overlap = verdict.overlap;
    nlohmann::json matrix = nlohmann::json::array();
    const Eigen::Matrix4d T = verdict.T_match_query.matrix();
    for (int row = 0; row < 4; ++row) {
        matrix.push_back({T(row, 0), T(row, 1), T(row, 2), T(row, 3)});
    }
    nlohmann::json json;
    json["accepted"] = verdict.accepted;
    json["reason"] = registration::ToString(verdict.reason);
    json["T_match_query"] = verdict.Registered() ? matrix : nlohmann::json(nullptr);
    json["overlap"] = overlap.Min();
    json["overlap_query"] = overlap.query_fraction;
    json["overlap_match"] = overlap.match_fraction;
    json["distinctive_overlap"] = overlap.MinDistinctive();
    json["distinctive_overlap_query"] = overlap.query_distinctive_fraction;
    json["distinctive_overlap_match"] = overlap.match_distinctive_fraction;
    json["overlapping_points_query"] = overlap.query_overlapping;
    json["overlapping_points_match"] = overlap.match_overlapping;
    json["rmse_m"] = overlap.rmse_m;
    json["shifted_overlap"] = std::isnan(verdict.shifted_overlap_ratio)
                                  ? nlohmann::json(nullptr)
                                  : nlohmann::json(verdict.shifted_overlap_ratio);
    json["coarse_score"] = verdict.coarse_score;
    json["icp_iterations"] = verdict.icp_iterations;
    return json;
}

}  // namespace lidarloop::app
