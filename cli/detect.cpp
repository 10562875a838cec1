#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "dataset_options.hpp"
#include "descriptor_options.hpp"
#include "lidarloop/app/detection.hpp"
#include "lidarloop/core/descriptor.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/io/run_record.hpp"
#include "odometry_options.hpp"
#include "progress.hpp"
#include "run_options.hpp"
#include "run_output.hpp"

namespace lidarloop::cli {
namespace {

struct DetectFlags {
    DatasetOptions dataset;
    DescriptorOptions descriptor;
    RunOptionFlags options;  // app/run_options.hpp: --threshold, --top-k, --skip-bad, ...
    std::string out;
    std::string map;           // a database.lldb to localise against (query-only mode)
    OdometryOptions odometry;  // the path (a gap in metres, path_m), submaps, the gate
    bool overwrite = false;
    bool quiet = false;
};

// The map fixes how scans are described (and RunLocalise takes its threshold unless one is
// given); flags and --config may set detection keys only.
io::RunConfig ResolveAgainstMap(const DetectFlags& flags, const app::LoadedMap& map) {
    io::RunConfig base;
    base.descriptor = map.database.config();
    io::RunConfig config = flags.descriptor.Resolve(base);
    bool skip_bad = false;  // set again by RunDetect
    flags.options.ApplyTo({&config, &skip_bad});
    if (config.descriptor != map.database.config()) {
        throw core::ConfigError(flags.descriptor.FirstGiven() +
                                " changes how scans are described, but the map " + flags.map +
                                " fixes that (its config.yaml beside it shows how)");
    }
    return config;
}

// "1 scan", "2 scans".
std::string Scans(std::size_t count) {
    return std::to_string(count) + (count == 1 ? " scan" : " scans");
}

// "12.3", or "0.05" below 1.
std::string FormatRate(double value) {
    char text[32];
    std::snprintf(text, sizeof(text), value < 1.0 ? "%.2f" : "%.1f", value);
    return text;
}

// The files of the results folder, as its run.json lists them.
std::string WrittenFiles(const std::filesystem::path& out) {
    const std::optional<io::RunRecord> record = io::ReadRunRecord(out);
    std::string text;
    for (const std::string& file : record ? record->files : std::vector<std::string>{})
        text += (text.empty() ? "" : ", ") + file;
    return text;
}

void PrintOutcome(const io::Dataset& dataset, const app::DetectRequest& request,
                  const app::DetectOutcome& outcome, const std::string& map) {
    std::cout << "lidarloop detect: " << Scans(dataset.size()) << " (" << dataset.FormatName()
              << ")";
    if (!map.empty()) {
        std::cout << " localised against the map " << map << " (" << Scans(outcome.map_scans)
                  << ")";
    }
    std::cout << ", method " << core::ToString(request.config.descriptor.method) << ", threshold "
              << outcome.threshold << ", " << Scans(outcome.accepted) << " with an accepted "
              << (map.empty() ? "loop" : "match");
    if (!outcome.skipped.empty()) std::cout << ", " << outcome.skipped.size() << " skipped";
    if (outcome.total_s > 0.0) {
        std::cout << "; " << FormatRate(static_cast<double>(dataset.size()) / outcome.total_s)
                  << " scans/s (" << FormatRate(outcome.total_s) << " s, files read included)";
    }
    std::cout << "\n  results in " << request.out.string() << "/ (" << WrittenFiles(request.out);
    if (!map.empty()) std::cout << "; loops.csv: query scan, map scan";
    if (map.empty() && !request.config.output.KeepsSimilarityMatrix(dataset.size()))
        std::cout << "; no similarity matrix: it would exceed output.similarity_matrix_mib";
    std::cout << ")\n";
    for (const std::string& note : outcome.notes) std::cerr << "lidarloop detect: " << note << '\n';
}

// The map and its database.scans beside it are inputs too.
std::vector<std::filesystem::path> Inputs(const DetectFlags& flags) {
    std::vector<std::filesystem::path> inputs = flags.dataset.Inputs();
    inputs.emplace_back(flags.map);
    inputs.emplace_back(flags.descriptor.config_file());
    for (const auto& input : flags.odometry.Inputs()) inputs.push_back(input);
    return inputs;
}

void RunDetect(const DetectFlags& flags) {
    ProgressPrinter progress(flags.quiet);
    app::DetectRequest request;
    request.progress = progress.Callback();
    request.out = flags.out;
    request.odometry_file = flags.odometry.file();
    request.odometry_topic = flags.odometry.topic();
    request.odometry_calib = flags.odometry.calib();
    if (!flags.map.empty()) {
        app::LoadedMap map = app::LoadMap(flags.map);
        request.config = ResolveAgainstMap(flags, map);
        flags.options.ApplyTo({&request.config, &request.skip_bad});
        const io::Dataset dataset = flags.dataset.Open();
        const app::DetectOutcome outcome = RunInFolder(
            flags.out, Inputs(flags), flags.overwrite, [&](const std::filesystem::path& staging) {
                app::DetectRequest staged = request;
                staged.out = staging;
                return app::RunLocalise(dataset, std::move(map), staged);
            });
        PrintOutcome(dataset, request, outcome, flags.map);
        return;
    }
    request.config = flags.descriptor.Resolve();
    flags.options.ApplyTo({&request.config, &request.skip_bad});
    const io::Dataset dataset = flags.dataset.Open();
    const app::DetectOutcome outcome = RunInFolder(flags.out, Inputs(flags), flags.overwrite,
                                                   [&](const std::filesystem::path& staging) {
                                                       app::DetectRequest staged = request;
                                                       staged.out = staging;
                                                       return app::RunDetect(dataset, staged);
                                                   });
    PrintOutcome(dataset, request, outcome, "");
}

}  // namespace

void AddDetectCommand(CLI::App& app) {
    auto* command = app.add_subcommand(
        "detect", "Find the loop closures of a sequence: candidates, similarity matrix, images");
    auto flags = std::make_shared<DetectFlags>();
    flags->dataset.AddTo(*command);
    flags->descriptor.AddTo(*command);
    flags->options.AddTo(*command, app::RunCommand::kDetect);
    command->add_option("--out", flags->out, "folder for the results (created)")->required();
    command
        ->add_option("--map", flags->map,
                     "localise against this database.lldb (written by an earlier detect): "
                     "every scan is a query, none is added, the map's descriptor config is used")
        ->check(CLI::ExistingFile);
    flags->odometry.AddTo(*command,
                          "the path a gap in metres and loops.csv's path_m are measured on "
                          "(default: the dataset's poses), what places each scan's neighbours in "
                          "its submap (without it: each scan's registration to the one before; "
                          "dense scans stay alone), "
                          "and what a registered loop must "
                          "agree with (reasons odometry_mismatch, unlike_fits, unlike_revisit)");
    command->add_flag("--overwrite", flags->overwrite,
                      "write into a non-empty folder that holds no earlier lidarloop run");
    command->add_flag("--quiet", flags->quiet, "no progress bar");
    command->callback([flags] { RunDetect(*flags); });
}

}  // namespace lidarloop::cli
