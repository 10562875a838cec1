#include <iostream>
#include <memory>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "dataset_options.hpp"
#include "descriptor_options.hpp"
#include "detection_options.hpp"
#include "lidarloop/app/bench.hpp"
#include "lidarloop/app/results_folder.hpp"
#include "lidarloop/app/run_folder.hpp"
#include "progress.hpp"

namespace lidarloop::cli {
namespace {

struct BenchFlags {
    DatasetOptions dataset;
    DescriptorOptions descriptor;
    DetectionOptions detection;
    app::BenchRequest request;
    std::string json;
    bool overwrite = false;
    bool quiet = false;
};

void RunBench(BenchFlags& flags) {
    ProgressPrinter progress(flags.quiet);
    flags.request.config = flags.descriptor.Resolve();
    flags.detection.ApplyTo(flags.request.config);
    flags.request.progress = progress.Callback();
    // The file is checked before the run, so that a refused --json costs no measurement.
    if (!flags.json.empty())
        app::CheckOutputFile(flags.json, flags.dataset.Inputs(), flags.overwrite);
    const nlohmann::json figures = app::RunBench(flags.dataset.Open(), flags.request);
    std::cout << figures.dump(2) << "\n";
    if (!flags.json.empty())
        app::WriteOutputJson(flags.json, figures, flags.dataset.Inputs(), flags.overwrite);
}

}  // namespace

void AddBenchCommand(CLI::App& app) {
    auto* command = app.add_subcommand(
        "bench", "Time descriptors, comparisons, the similarity matrix and queries on a dataset");
    auto flags = std::make_shared<BenchFlags>();
    flags->dataset.AddTo(*command);
    flags->descriptor.AddTo(*command);
    command->add_option("--queries", flags->request.queries, "query scans to time (default 200)");
    command->add_option("--scale-to", flags->request.scale_to,
                        "also time queries against this many stored histograms (synthetic)");
    command->add_option("--verify-queries", flags->request.verify_queries,
                        "query scans whose top-k candidates are verified and timed (default 50; "
                        "0: none)");
    flags->detection.AddTo(*command, /*decides_loops=*/true,
                           "S: candidates at least this far back");
    command->add_option("--json", flags->json,
                        "also write the figures to this file (replaced only when lidarloop wrote "
                        "it, or with --overwrite)");
    command->add_flag("--overwrite", flags->overwrite,
                      "let --json replace a file that lidarloop did not write");
    command->add_flag("--quiet", flags->quiet, "no progress bar");
    command->callback([flags] { RunBench(*flags); });
}

}  // namespace lidarloop::cli
