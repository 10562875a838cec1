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

void RunDetect(const DetectFlags& flags) {
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

    nlohmann::json timings = TimingsJson(described, matrix.condensed().size(), matrix_s);
    timings["describe_total_s"] = describe_s;
    timings["total_s"] = total.Seconds();
    WriteJson(out_dir / "timings.json", timings);

    std::size_t accepted = 0;
    for (const auto& q : queries) accepted += q.accepted ? 1 : 0;
    std::cout << "lidarloop detect: " << dataset.size() << " scans (" << dataset.FormatName()
              << "), method " << core::ToString(config.descriptor.method) << ", threshold "
              << threshold << ", " << accepted << " scans with an accepted loop";
    if (!described.skipped.empty()) std::cout << ", " << described.skipped.size() << " skipped";
    std::cout << "\n  results in " << out_dir.string()
              << "/ (loops.csv, candidates.csv, similarity.png, similarity_distance.png,"
                 " similarity.bin, config.yaml, timings.json)\n";
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
    command->add_flag("--skip-bad", flags->skip_bad,
                      "skip unreadable scans (listed in skipped.txt) instead of stopping");
    command->add_flag("--quiet", flags->quiet, "no progress bar");
    command->callback([flags] { RunDetect(*flags); });
}

}  // namespace lidarloop::cli
