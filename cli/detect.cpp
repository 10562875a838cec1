#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "dataset_options.hpp"
#include "descriptor_options.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/io/database_file.hpp"
#include "lidarloop/io/read_error.hpp"
#include "lidarloop/io/similarity_file.hpp"
#include "lidarloop/io/similarity_image.hpp"
#include "lidarloop/pipeline/loop_detector.hpp"
#include "run_output.hpp"

namespace lidarloop::cli {
namespace {

struct DetectFlags {
    DatasetOptions dataset;
    DescriptorOptions descriptor;
    DetectionOptions detection;
    std::string out;
    std::string map;  // a database.lldb to localise against (query-only mode)
    bool skip_bad = false;
    bool quiet = false;
};

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

// The map fixes how scans are described; flags and --config may set thresholds and detection
// keys only.
io::RunConfig ResolveAgainstMap(const DetectFlags& flags, const pipeline::DescriptorDatabase& map) {
    io::RunConfig base;
    base.descriptor = map.config();
    io::RunConfig config = flags.descriptor.Resolve(base);
    flags.detection.ApplyTo(config);
    if (!core::DescribesAlike(config.descriptor, map.config())) {
        throw core::ConfigError(flags.descriptor.FirstGiven() +
                                " changes how scans are described, but the map " + flags.map +
                                " fixes that (its config.yaml beside it shows how)");
    }
    return config;
}

// Query-only mode: every scan of the dataset is searched in the map and not added to it.
void RunLocalise(const DetectFlags& flags) {
    Stopwatch total;
    Stopwatch load_clock;
    pipeline::DescriptorDatabase map = io::LoadDatabase(flags.map);
    const io::RunConfig config = ResolveAgainstMap(flags, map);
    const pipeline::LoopDetector detector(std::move(map), config.detection,
                                          core::DefaultThreshold(config.descriptor));
    const double load_map_s = load_clock.Seconds();
    const io::Dataset dataset = flags.dataset.Open();
    const std::filesystem::path out_dir = PrepareOutputFolder(flags.out);
    io::WriteConfigYaml(out_dir / "config.yaml", config);

    const pipeline::SequenceDescriptors described =
        DescribeDataset(dataset, config.descriptor, {"describing", flags.skip_bad, flags.quiet});
    Stopwatch query_clock;
    const auto queries = pipeline::LocaliseSequence(detector, described.database);
    const double query_s = query_clock.Seconds();

    WriteLoopsCsv(out_dir / "loops.csv", queries);
    WriteCandidatesCsv(out_dir / "candidates.csv", queries);
    WriteSkipped(out_dir, described.skipped);
    nlohmann::json timings = DescribeTimingsJson(described);
    timings["map"] = flags.map;
    timings["map_scans"] = detector.database().size();
    timings["load_map_s"] = load_map_s;
    timings["query_ms_per_scan_wall"] =
        queries.empty() ? 0.0 : 1e3 * query_s / static_cast<double>(queries.size());
    timings["total_s"] = total.Seconds();
    WriteJson(out_dir / "timings.json", timings);

    std::cout << "lidarloop detect: " << dataset.size() << " scans (" << dataset.FormatName()
              << ") localised against the map " << flags.map << " (" << detector.database().size()
              << " scans), method " << core::ToString(config.descriptor.method) << ", threshold "
              << detector.threshold() << ", " << CountAccepted(queries)
              << " scans with an accepted match";
    if (!described.skipped.empty()) std::cout << ", " << described.skipped.size() << " skipped";
    std::cout << "\n  results in " << out_dir.string()
              << "/ (loops.csv: query scan, map scan; candidates.csv, config.yaml, timings.json)\n";
}

void RunDetect(const DetectFlags& flags) {
    if (!flags.map.empty()) {
        RunLocalise(flags);
        return;
    }
    io::RunConfig config = flags.descriptor.Resolve();
    flags.detection.ApplyTo(config);
    const io::Dataset dataset = flags.dataset.Open();
    RequireTimesForSeconds(config, dataset);
    const std::filesystem::path out_dir = PrepareOutputFolder(flags.out);
    io::WriteConfigYaml(out_dir / "config.yaml", config);

    Stopwatch total;
    Stopwatch describe_clock;
    const pipeline::SequenceDescriptors described =
        DescribeDataset(dataset, config.descriptor, {"describing", flags.skip_bad, flags.quiet});
    const double describe_s = describe_clock.Seconds();

    Stopwatch matrix_clock;
    const pipeline::SimilarityMatrix matrix = pipeline::ComputeSimilarityMatrix(described.database);
    const double matrix_s = matrix_clock.Seconds();
    const double threshold = core::DefaultThreshold(config.descriptor);
    const auto queries =
        pipeline::DetectFromMatrix(matrix, described.database.times_s(), config.detection,
                                   config.descriptor.method, threshold);

    WriteLoopsCsv(out_dir / "loops.csv", queries);
    WriteCandidatesCsv(out_dir / "candidates.csv", queries);
    io::WriteSimilarityMatrix(out_dir / "similarity.bin", matrix, config.descriptor.method);
    io::WritePng(out_dir / "similarity.png",
                 io::ThresholdImage(matrix, config.descriptor.method, threshold));
    io::WritePng(out_dir / "similarity_distance.png", io::DistanceImage(matrix));
    WriteSkipped(out_dir, described.skipped);
    io::SaveDatabase(out_dir / "database.lldb", described.database);

    nlohmann::json timings = TimingsJson(described, matrix.condensed().size(), matrix_s);
    timings["describe_total_s"] = describe_s;
    timings["total_s"] = total.Seconds();
    WriteJson(out_dir / "timings.json", timings);

    std::cout << "lidarloop detect: " << dataset.size() << " scans (" << dataset.FormatName()
              << "), method " << core::ToString(config.descriptor.method) << ", threshold "
              << threshold << ", " << CountAccepted(queries) << " scans with an accepted loop";
    if (!described.skipped.empty()) std::cout << ", " << described.skipped.size() << " skipped";
    std::cout << "\n  results in " << out_dir.string()
              << "/ (loops.csv, candidates.csv, similarity.png, similarity_distance.png,"
                 " similarity.bin, database.lldb, config.yaml, timings.json)\n";
}

}  // namespace

void AddDetectCommand(CLI::App& app) {
    auto* command = app.add_subcommand(
        "detect", "Find the loop closures of a sequence: candidates, similarity matrix, images");
    auto flags = std::make_shared<DetectFlags>();
    flags->dataset.AddTo(*command);
    flags->descriptor.AddTo(*command);
    flags->detection.AddTo(*command);
    command->add_option("--out", flags->out, "folder for the results (created)")->required();
    command
        ->add_option("--map", flags->map,
                     "localise against this database.lldb (written by an earlier detect): "
                     "every scan is a query, none is added, the map's descriptor config is used")
        ->check(CLI::ExistingFile);
    command->add_flag("--skip-bad", flags->skip_bad,
                      "skip unreadable scans (listed in skipped.txt) instead of stopping");
    command->add_flag("--quiet", flags->quiet, "no progress bar");
    command->callback([flags] { RunDetect(*flags); });
}

}  // namespace lidarloop::cli
