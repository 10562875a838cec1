// Replays the verifications of a `lidarloop detect` run from its saved prepared scans: every
// registered candidate of candidates.csv is verified again with this build, timed on the calling
// thread, and its verdict compared with the run's. The A/B harness for verification changes
// (docs/BENCHMARK.md): same decisions and poses, time per pair. Run:
//   taskset -c 1 ./build/bench/verify_replay RUN [--config FILE] [--compact]
//                                            [--pairs-csv FILE [--poses FILE]]
//                                            [--odometry FILE]
//                                            [--submap-scans DIR --submap-poses FILE
//                                             --submap-window-m M [--submap-max-scans N]
//                                             [--submap-query past|full]]
// RUN_FOLDER holds database.scans, candidates.csv and config.yaml (detect with verification on);
// --config verifies with another configuration, --compact with the scans kept compact (the
// match expanded in the timed step, as detect does), --pairs-csv writes one line per pair (verdict,
// coarse score, occupied image cells, overlaps, ICP iterations, time, both scans' point counts
// and roughness, overlapping points, RMSE and the RMSE allowed, the degeneracy measures, the
// coarse search's time alone, its best score, hypothesis count and the 2nd and 3rd's score over it,
// the hypotheses ICP refined, and the rank of the hypothesis the registered pose came from) and,
// with --poses (KITTI or TUM, T_world_sensor, one per scan), the true distance, the overlap at the
// true pose and the registered pose's error against it (metres, degrees).
// --odometry (KITTI or TUM, T_world_sensor, one per scan): the odometry's word as `detect
// --odometry` applies it (app::OdometryLoopCheck with the run's pose-graph gate): the yaws and
// poses its gate allows, its looser bars, and odometry_mismatch for an accepted pose it
// contradicts; without it a replay of such a run judges its pairs as if it had none.
// --submap-*: each match is the scan merged with its neighbours within M metres of path (at most
// N a side; of those, the nearest within the configuration's submap_max_points, as detect
// merges them), placed by the poses given (odometry: the ground truth is for scoring only) and
// prepared as one scan from the raw scans in DIR; --submap-query merges the query's past alike
// (past) or both sides as the match (full: offline, all scans exist).
// The question of issue 24: whether a denser match side closes the sparse revisits.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "lidarloop/app/results_folder.hpp"
#include "lidarloop/app/verification_run.hpp"
#include "lidarloop/core/min_gap.hpp"
#include "lidarloop/io/config_yaml.hpp"
#include "lidarloop/io/dataset.hpp"
#include "lidarloop/io/poses.hpp"
#include "lidarloop/io/prepared_scans_file.hpp"
#include "lidarloop/registration/compact_prepared_scan.hpp"
#include "lidarloop/registration/submap.hpp"
#include "lidarloop/registration/verification.hpp"

namespace {

using namespace lidarloop;

// One registered candidate of candidates.csv and the run's verdict.
struct Candidate {
    std::size_t query = 0;
    std::size_t match = 0;
    bool accepted = false;
    std::string reason;
    Eigen::Vector3d translation_m = Eigen::Vector3d::Zero();
};

std::vector<std::string> Fields(const std::string& line) {
    std::vector<std::string> fields;
    std::stringstream stream(line);
    for (std::string field; std::getline(stream, field, ',');) fields.push_back(field);
    return fields;
}

std::vector<Candidate> ReadCandidates(const std::filesystem::path& file) {
    std::ifstream in(file);
    if (!in) throw std::runtime_error("cannot read " + file.string());
    std::string line;
    std::getline(in, line);
    const auto header = Fields(line);
    const auto column = [&](const std::string& name) {
        const auto it = std::find(header.begin(), header.end(), name);
        if (it == header.end()) throw std::runtime_error(file.string() + " has no column " + name);
        return static_cast<std::size_t>(it - header.begin());
    };
    const std::size_t query = column("query"), match = column("match"),
                      accepted = column("accepted"), reason = column("reason"), tx = column("tx");
    std::vector<Candidate> candidates;
    while (std::getline(in, line)) {
        const auto fields = Fields(line);
        if (fields.size() != header.size() || fields[reason] == "pruned" ||
            fields[reason] == "not_needed") {
            continue;
        }
        // Rejected by the sequence (the neighbours, the query's other fits, the revisit's other
        // loops, the scans' motion), not by the pair: a replay of the pair alone accepts it.
        const bool rejected_by_the_sequence =
            fields[reason] == "unlike_neighbours" || fields[reason] == "unlike_fits" ||
            fields[reason] == "unlike_revisit" || fields[reason] == "unlike_motion";
        Candidate candidate{std::stoul(fields[query]), std::stoul(fields[match]),
                            fields[accepted] == "1" || rejected_by_the_sequence, fields[reason]};
        for (int i = 0; i < 3; ++i) {
            if (!fields[tx + i].empty()) candidate.translation_m[i] = std::stod(fields[tx + i]);
        }
        candidates.push_back(candidate);
    }
    return candidates;
}

double Mean(const std::vector<double>& values) {
    double sum = 0.0;
    for (const double value : values) sum += value;
    return values.empty() ? 0.0 : sum / static_cast<double>(values.size());
}

struct Tally {
    std::size_t pairs = 0, same_verdict = 0, accepted_before = 0, accepted_now = 0;
    std::size_t lost = 0, gained = 0;  // accepted before and not now, and the reverse
    double max_translation_change_m = 0.0;
    std::vector<double> pair_ms, query_ms;
    std::map<std::string, std::size_t> reasons_now;
};

// The occupied cells of a scan's top-down structure image (the coarse search's input).
std::size_t OccupiedCells(const registration::SurfacePoints& structure,
                          const registration::CoarseConfig& config) {
    const auto image = registration::OccupancyImage(structure.points(), 0.0, config);
    return static_cast<std::size_t>(std::count(image.begin(), image.end(), 1.0F));
}

// The rank (0: best) of the coarse hypothesis the registered pose came from: the first within 2 m
// and 10 degrees of it (-1 when none is; ICP moved it farther). Which peaks the verdicts need.
int HypothesisRankOf(const std::vector<registration::PlanarHypothesis>& hypotheses,
                     const core::Transform& T_registered) {
    const double yaw_rad = std::atan2(T_registered.linear()(1, 0), T_registered.linear()(0, 0));
    for (std::size_t rank = 0; rank < hypotheses.size(); ++rank) {
        const double yaw_error_rad =
            std::abs(std::remainder(hypotheses[rank].yaw_rad - yaw_rad, 2.0 * M_PI));
        const double offset_m =
            (hypotheses[rank].translation_m - T_registered.translation().head<2>()).norm();
        if (offset_m < 2.0 && yaw_error_rad < 10.0 * M_PI / 180.0) return static_cast<int>(rank);
    }
    return -1;
}

// The rank (0: best) of the first coarse hypothesis within 2 m and 10 degrees of the true planar
// pose, -1 when none is: whether the coarse search or ICP lost a pair.
int CoarseRankOfTruth(const registration::PreparedScan& query,
                      const registration::PreparedScan& match, const core::Transform& T_truth,
                      const registration::VerificationConfig& config) {
    const registration::CoarseQuery coarse(*query.structure, config.coarse);
    return HypothesisRankOf(registration::CoarseAlign(coarse, *match.structure), T_truth);
}

// Coarse score of hypothesis `rank` over the best's, 0 when there is none.
double ScoreRatio(const std::vector<registration::PlanarHypothesis>& hypotheses, std::size_t rank) {
    return rank < hypotheses.size() ? hypotheses[rank].score / hypotheses.front().score : 0.0;
}

// With ground-truth poses: the sensors' distance and the overlap at the true relative pose (what
// the pair can show at best), as CSV fields; empty fields without poses.
std::string TruthFields(const std::vector<core::StampedPose>& poses, const Candidate& candidate,
                        const registration::PreparedScan& query,
                        const registration::PreparedScan& match,
                        const registration::VerificationConfig& config,
                        const registration::Verification& now) {
    if (poses.empty()) return ",,,,,";
    const core::Transform T_match_query = poses.at(candidate.match).T_world_sensor.inverse() *
                                          poses.at(candidate.query).T_world_sensor;
    const registration::Overlap overlap =
        registration::MeasureOverlap(query, match, T_match_query, config.acceptance);
    std::ostringstream fields;
    fields << T_match_query.translation().norm() << ',' << overlap.Min() << ','
           << overlap.MinDistinctive() << ','
           << CoarseRankOfTruth(query, match, T_match_query, config) << ',';
    // A pair never registered has no pose to be wrong: empty error fields.
    if (!now.Registered()) return fields.str() + ',';
    const core::Transform& T_registered = now.T_match_query;
    fields
        << (T_registered.translation() - T_match_query.translation()).norm() << ','
        << Eigen::AngleAxisd(T_registered.linear().transpose() * T_match_query.linear()).angle() *
               180.0 / M_PI;
    return fields.str();
}

// The registered sensors' distance, metres, formatted as the other fields; empty for a pair
// never registered (every coarse peak out of reach), whose pose is no registration's.
std::string RegisteredDistance(const registration::Verification& now) {
    std::ostringstream field;
    if (now.Registered()) field << now.T_match_query.translation().norm();
    return field.str();
}

// A scan's structure points, distinctive ones among them, ground points and roughness.
std::string ScanFields(const registration::PreparedScan& scan) {
    std::ostringstream fields;
    fields << scan.structure->size() << ','
           << std::count(scan.structure_distinctive.begin(), scan.structure_distinctive.end(), 1)
           << ',' << scan.ground->size() << ',' << scan.structure_roughness_m;
    return fields.str();
}

// One line of --pairs-csv: the verdict now, what the coarse search saw and, with poses, the truth.
void WritePair(std::ofstream& out, const Candidate& candidate,
               const registration::Verification& now, const registration::PreparedScan& query,
               const registration::PreparedScan& match,
               const registration::VerificationConfig& config, double ms,
               const std::vector<core::StampedPose>& poses,
               const std::vector<registration::PlanarHypothesis>& hypotheses, double coarse_ms) {
    out << candidate.query << ',' << candidate.match << ',' << (now.accepted ? 1 : 0) << ','
        << registration::ToString(now.reason) << ',' << now.coarse_score << ','
        << OccupiedCells(*query.structure, config.coarse) << ','
        << OccupiedCells(*match.structure, config.coarse) << ',' << now.overlap.Min() << ','
        << now.overlap.MinDistinctive() << ',' << now.icp_iterations << ',' << ms << ','
        << TruthFields(poses, candidate, query, match, config, now) << ',' << ScanFields(query)
        << ',' << ScanFields(match) << ',' << now.overlap.query_overlapping << ','
        << now.overlap.match_overlapping << ',' << now.overlap.rmse_m << ','
        << registration::AllowedRmse(query, match, config.acceptance) << ','
        << now.overlap.shifted_overlap_ratio << ',' << now.overlap.constraining_points << ','
        << RegisteredDistance(now) << ',' << coarse_ms << ','
        << (hypotheses.empty() ? 0.0 : hypotheses.front().score) << ',' << hypotheses.size() << ','
        << ScoreRatio(hypotheses, 1) << ',' << ScoreRatio(hypotheses, 2) << ','
        << now.registered_hypotheses << ','
        << (now.overlap.query_overlapping == 0 ? -2
                                               : HypothesisRankOf(hypotheses, now.T_match_query))
        << ',' << now.overlap.query_in_view << ',' << now.overlap.match_in_view << '\n';
}

// The run's scans as a run keeps them: as loaded, or (--compact) encoded as
// registration::CompactPreparedScan and expanded when used, as detect does.
class ScanSource {
public:
    ScanSource(std::vector<registration::PreparedScan> scans, bool compact) {
        if (!compact) {
            scans_ = std::move(scans);
            return;
        }
        for (const auto& scan : scans) compact_.emplace_back(scan);
    }
    registration::PreparedScan At(std::size_t i) const {
        return compact_.empty() ? scans_.at(i) : compact_.at(i).Expand();
    }

private:
    std::vector<registration::PreparedScan> scans_;
    std::vector<registration::CompactPreparedScan> compact_;
};

// Scans prepared from their submaps (see the header), each once, and the time that took.
class SubmapSource {
public:
    SubmapSource(const std::filesystem::path& scans, const std::filesystem::path& poses,
                 const registration::SubmapWindow& window,
                 const registration::ScanReductionConfig& reduction)
        : dataset_(io::OpenDataset(scans)),
          poses_(io::ReadPoses(poses)),
          path_m_(registration::SubmapPathM(poses_)),
          window_(window),
          reduction_(reduction) {
        if (poses_.size() != dataset_.size())
            throw std::runtime_error("--submap-poses: not one pose per scan");
    }
    registration::PreparedScan At(std::size_t i, bool past_only) {
        auto& cache = past_only ? past_ : both_;
        if (const auto it = cache.find(i); it != cache.end()) return it->second;
        const app::ThreadCpuStopwatch clock;
        registration::SubmapWindow window = window_;
        window.past_only = past_only;
        const std::vector<std::size_t> members = registration::SubmapMembers(path_m_, i, window);
        members_.push_back(static_cast<double>(members.size()));
        const registration::PreparedScan prepared = past_only ? PastOnly(i, members) : BothSides(i);
        prepare_ms_.push_back(1e3 * clock.Seconds());
        return cache.emplace(i, prepared).first->second;
    }
    // As detect prepares it: the window, then its nearest scans within the point budget.
    registration::PreparedScan BothSides(std::size_t i) const {
        registration::ScanReductionConfig reduction = reduction_;
        reduction.submap_path_m = window_.path_m;
        reduction.submap_max_scans = window_.max_scans;
        return registration::PrepareSubmap(
            i, poses_, path_m_, [this](std::size_t k) { return dataset_.LoadScan(k); }, reduction);
    }
    // What an online detector could have: the window's past, without the point budget.
    registration::PreparedScan PastOnly(std::size_t i,
                                        const std::vector<std::size_t>& members) const {
        std::vector<core::PointCloud> scans;
        std::vector<core::Transform> T_world_scans;
        for (const std::size_t k : members) {
            scans.push_back(dataset_.LoadScan(k));
            T_world_scans.push_back(poses_[k].T_world_sensor);
        }
        return registration::PrepareScan(
            scans.size() == 1 ? scans.front()
                              : registration::MergeIntoFrame(scans, T_world_scans,
                                                             poses_[i].T_world_sensor, reduction_),
            reduction_);
    }
    void Report() const {
        std::printf(
            "  submaps: %zu prepared, scans in the window median %.0f, prepare median %.1f ms\n",
            prepare_ms_.size(), app::Quantile(members_, 0.5), app::Quantile(prepare_ms_, 0.5));
    }

private:
    io::Dataset dataset_;
    std::vector<core::StampedPose> poses_;
    std::vector<double> path_m_;
    registration::SubmapWindow window_;
    registration::ScanReductionConfig reduction_;
    std::map<std::size_t, registration::PreparedScan> both_, past_;
    std::vector<double> members_, prepare_ms_;
};

// Where the replay takes a scan from: the run's stored scans, or a submap.
struct Sources {
    const ScanSource& stored;
    SubmapSource* submaps = nullptr;  // nullptr: stored scans only
    bool query_submap = false;
    bool query_past_only = true;
    registration::PreparedScan Query(std::size_t i) const {
        return submaps != nullptr && query_submap ? submaps->At(i, query_past_only) : stored.At(i);
    }
    registration::PreparedScan Match(std::size_t j) const {
        return submaps != nullptr ? submaps->At(j, false) : stored.At(j);
    }
};

// The yaw windows the check gives the candidates of `candidates[first]`'s query (its run).
std::vector<registration::YawWindow> QueryYaws(const std::vector<Candidate>& candidates,
                                               std::size_t first,
                                               const pipeline::LoopCheck& check) {
    std::vector<registration::YawWindow> yaws;
    for (std::size_t c = first;
         c < candidates.size() && candidates[c].query == candidates[first].query; ++c) {
        yaws.push_back(check.YawWindow(candidates[c].query, candidates[c].match));
    }
    return yaws;
}

// Verify as detect does under `check`: its yaws and poses, then its judgement of the verdict
// (the check detect runs on each verified query, here on a query of this one candidate).
registration::Verification VerifyUnder(const registration::PreparedScan& query,
                                       const registration::CoarseQuery& coarse,
                                       const registration::PreparedScan& match,
                                       const registration::VerificationConfig& config,
                                       const Candidate& candidate,
                                       const pipeline::LoopCheck& check) {
    const registration::Verification verdict = registration::Verify(
        query, coarse, match, config, check.AllowedPoses(candidate.query, candidate.match),
        check.YawWindow(candidate.query, candidate.match));
    if (!check) return verdict;
    pipeline::LoopQuery judged;
    judged.query = candidate.query;
    judged.candidates.push_back({candidate.match, 0.0});
    judged.verifications.push_back(verdict);
    check(judged);
    return judged.verifications.front();
}

void Replay(const std::filesystem::path& run, const registration::VerificationConfig& config,
            const std::filesystem::path& pairs_csv, const std::vector<core::StampedPose>& poses,
            bool compact, SubmapSource* submaps, bool query_submap, bool query_past_only,
            const pipeline::LoopCheck& check) {
    std::ofstream pairs;
    if (!pairs_csv.empty()) {
        pairs.open(pairs_csv);
        pairs << "query,match,accepted,reason,coarse_score,query_cells,match_cells,overlap,"
                 "distinctive_overlap,icp_iterations,ms,true_distance_m,true_overlap,"
                 "true_distinctive_overlap,coarse_rank_of_truth,pose_error_m,pose_error_deg,"
                 "q_structure,q_distinctive,q_ground,q_roughness_m,m_structure,m_distinctive,"
                 "m_ground,m_roughness_m,q_overlapping,m_overlapping,rmse_m,"
                 "allowed_rmse_m,"
                 "shifted_ratio,constraining,registered_distance_m,coarse_ms,top_coarse_score,"
                 "hypotheses,second_score_ratio,third_score_ratio,registered_hypotheses,"
                 "result_hypothesis,q_in_view,m_in_view\n";
    }
    io::StoredPreparedScans stored = io::LoadPreparedScans(run / "database.scans");
    const ScanSource stored_scans(std::move(stored.scans), compact);
    const Sources scans{stored_scans, submaps, query_submap, query_past_only};
    if (!(stored.reduction == config.reduction))
        std::printf("note: the scans were reduced with another configuration than --config's\n");
    const std::vector<Candidate> candidates = ReadCandidates(run / "candidates.csv");
    Tally tally;
    std::optional<registration::CoarseQuery> coarse;
    registration::PreparedScan query;
    std::size_t query_index = static_cast<std::size_t>(-1);
    for (std::size_t c = 0; c < candidates.size(); ++c) {
        const Candidate& candidate = candidates[c];
        if (query_index != candidate.query) {
            const app::ThreadCpuStopwatch clock;
            query = scans.Query(candidate.query);
            if (query.structure)
                coarse.emplace(*query.structure, config.coarse, QueryYaws(candidates, c, check));
            tally.query_ms.push_back(1e3 * clock.Seconds());
            query_index = candidate.query;
        }
        const app::ThreadCpuStopwatch clock;
        const registration::PreparedScan match = scans.Match(candidate.match);
        if (!query.structure || !match.structure) continue;
        const registration::Verification now =
            VerifyUnder(query, *coarse, match, config, candidate, check);
        tally.pair_ms.push_back(1e3 * clock.Seconds());
        if (pairs.is_open()) {
            // The coarse search alone, timed again (Verify above includes it).
            const app::ThreadCpuStopwatch coarse_clock;
            const auto hypotheses = registration::CoarseAlign(
                *coarse, *match.structure, check.YawWindow(candidate.query, candidate.match));
            const double coarse_ms = 1e3 * coarse_clock.Seconds();
            WritePair(pairs, candidate, now, query, match, config, tally.pair_ms.back(), poses,
                      hypotheses, coarse_ms);
        }
        ++tally.pairs;
        tally.accepted_before += candidate.accepted ? 1 : 0;
        tally.accepted_now += now.accepted ? 1 : 0;
        tally.same_verdict += now.accepted == candidate.accepted ? 1 : 0;
        tally.lost += candidate.accepted && !now.accepted ? 1 : 0;
        tally.gained += !candidate.accepted && now.accepted ? 1 : 0;
        ++tally.reasons_now[registration::ToString(now.reason)];
        if (candidate.accepted && now.accepted) {
            tally.max_translation_change_m =
                std::max(tally.max_translation_change_m,
                         (now.T_match_query.translation() - candidate.translation_m).norm());
        }
    }
    std::printf("%s: %zu pairs, %zu queries\n", run.c_str(), tally.pairs, tally.query_ms.size());
    std::printf(
        "  verdicts: %zu same, accepted %zu -> %zu (lost %zu, gained %zu), accepted "
        "translation changed by at most %.4f m\n",
        tally.same_verdict, tally.accepted_before, tally.accepted_now, tally.lost, tally.gained,
        tally.max_translation_change_m);
    std::printf("  reasons now:");
    for (const auto& [reason, count] : tally.reasons_now)
        std::printf(" %s %zu", reason.c_str(), count);
    std::printf(
        "\n  thread CPU: per pair median %.3f ms, p95 %.3f ms, mean %.3f ms; coarse "
        "images per query median %.3f ms\n",
        app::Quantile(tally.pair_ms, 0.5), app::Quantile(tally.pair_ms, 0.95), Mean(tally.pair_ms),
        app::Quantile(tally.query_ms, 0.5));
    if (submaps != nullptr) submaps->Report();
}

}  // namespace

int main(int argc, char** argv) {
    std::filesystem::path run, config_file, pairs_csv, poses_file, odometry_file, submap_scans,
        submap_poses;
    registration::SubmapWindow window{0.0, 1000, false};
    bool compact = false, query_submap = false, query_past_only = true;
    for (int i = 1; i < argc; ++i) {
        const std::string argument = argv[i];
        if (argument == "--compact") {
            compact = true;
        } else if (argument == "--config" && i + 1 < argc) {
            config_file = argv[++i];
        } else if (argument == "--pairs-csv" && i + 1 < argc) {
            pairs_csv = argv[++i];
        } else if (argument == "--poses" && i + 1 < argc) {
            poses_file = argv[++i];
        } else if (argument == "--odometry" && i + 1 < argc) {
            odometry_file = argv[++i];
        } else if (argument == "--submap-scans" && i + 1 < argc) {
            submap_scans = argv[++i];
        } else if (argument == "--submap-poses" && i + 1 < argc) {
            submap_poses = argv[++i];
        } else if (argument == "--submap-window-m" && i + 1 < argc) {
            window.path_m = std::stod(argv[++i]);
        } else if (argument == "--submap-max-scans" && i + 1 < argc) {
            window.max_scans = std::stoi(argv[++i]);
        } else if (argument == "--submap-query" && i + 1 < argc) {
            // past: the query's past only (online); full: both sides, as the match (offline).
            query_submap = true;
            query_past_only = std::string(argv[++i]) != "full";
        } else if (run.empty() && argument.rfind("--", 0) != 0) {
            run = argument;
        } else {
            run.clear();
            break;
        }
    }
    if (run.empty()) {
        std::fprintf(
            stderr,
            "usage: %s RUN_FOLDER [--config FILE] [--compact] [--pairs-csv FILE [--poses FILE]]\n"
            "       [--odometry FILE]\n"
            "       [--submap-scans DIR --submap-poses FILE --submap-window-m M\n"
            "        [--submap-max-scans N] [--submap-query past|full]]\n",
            argv[0]);
        return 2;
    }
    try {
        const io::RunConfig config =
            io::LoadConfigYaml(config_file.empty() ? run / "config.yaml" : config_file);
        const std::vector<core::StampedPose> poses =
            poses_file.empty() ? std::vector<core::StampedPose>{} : io::ReadPoses(poses_file);
        std::optional<SubmapSource> submaps;
        if (!submap_scans.empty()) {
            submaps.emplace(submap_scans, submap_poses, window,
                            config.detection.verification.reduction);
        }
        const std::vector<core::StampedPose> odometry =
            odometry_file.empty() ? std::vector<core::StampedPose>{} : io::ReadPoses(odometry_file);
        const std::vector<double> path_m = core::CumulativePathM(odometry);
        const pipeline::LoopCheck check =
            odometry.empty() ? pipeline::LoopCheck{}
                             : app::OdometryLoopCheck(odometry, path_m, config.posegraph);
        Replay(run, config.detection.verification, pairs_csv, poses, compact,
               submaps ? &*submaps : nullptr, query_submap, query_past_only, check);
    } catch (const std::exception& error) {
        std::fprintf(stderr, "verify_replay: %s\n", error.what());
        return 1;
    }
    return 0;
}
