#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "dataset_options.hpp"
#include "descriptor_options.hpp"
#include "lidarloop/app/bench.hpp"
#include "lidarloop/app/results_folder.hpp"
#include "lidarloop/app/run_folder.hpp"
#include "odometry_options.hpp"
#include "progress.hpp"
#include "run_options.hpp"

namespace lidarloop::cli {
namespace {

struct BenchFlags {
    DatasetOptions dataset;
    DescriptorOptions descriptor;
    RunOptionFlags options;    // app/run_options.hpp: --threshold, --top-k, --min-gap, ...
    OdometryOptions odometry;  // the reach, order and gate of the timed verification
    app::BenchRequest request;
    std::string json;
    const CLI::Option* json_option = nullptr;  // given, even as --json '' (refused)
    bool overwrite = false;
    bool quiet = false;
};

// "12.3 ms" with sensible precision; microseconds below 0.1 ms.
std::string Duration(double ms) {
    char text[32];
    if (ms < 0.1) {
        std::snprintf(text, sizeof(text), "%.2f us", 1e3 * ms);
    } else {
        std::snprintf(text, sizeof(text), ms < 10.0 ? "%.2f ms" : "%.1f ms", ms);
    }
    return text;
}

// A figure of the table: "-" where nothing was timed (null; ASCII keeps the columns aligned), ""
// where the summary has no such figure.
std::string Figure(const nlohmann::json& summary, const char* statistic, double scale) {
    if (!summary.contains(statistic)) return "";
    const nlohmann::json& value = summary[statistic];
    return value.is_number() ? Duration(scale * value.get<double>()) : "-";
}

void PrintRow(const std::string& stage, const std::string& per, const nlohmann::json& summary,
              double scale = 1.0) {
    std::printf("| %-44s | %-14s | %10s | %10s |\n", stage.c_str(), per.c_str(),
                Figure(summary, "median", scale).c_str(), Figure(summary, "p95", scale).c_str());
}

// The figures as a table a user reads: the stages of the online step and their sum.
void PrintSummary(const nlohmann::json& figures) {
    std::printf("lidarloop bench: %d scans, method %s (medians and 95th percentiles)\n\n",
                figures.value("scans", 0), figures.value("method", std::string()).c_str());
    std::printf("| %-44s | %-14s | %10s | %10s |\n", "stage", "per", "median", "p95");
    std::printf("|%s|%s|%s|%s|\n", std::string(46, '-').c_str(), std::string(16, '-').c_str(),
                std::string(12, '-').c_str(), std::string(12, '-').c_str());
    PrintRow("read the file", "scan", figures["load_ms_per_scan"]);
    PrintRow("describe", "scan", figures["describe_ms_per_scan"]);
    const nlohmann::json& queries = figures["queries"];
    if (queries.contains("index_us")) {
        PrintRow("retrieval (index)", "query", queries["index_us"], 1e-3);
    } else {
        PrintRow("retrieval (every scan compared)", "query", queries["brute_force_us"], 1e-3);
    }
    if (figures.contains("scaled_queries")) {
        const nlohmann::json& scaled = figures["scaled_queries"];
        PrintRow("retrieval (index), " + std::to_string(scaled.value("stored_histograms", 0)) +
                     " stored (synthetic)",
                 "query", scaled["index_us"], 1e-3);
    }
    double online_ms = 0.0;
    if (figures.contains("verification")) {
        const nlohmann::json& verification = figures["verification"];
        PrintRow("candidates found and ordered (CPU)", "query",
                 verification["candidates_ms_per_query"]);
        PrintRow("prepare for verification (CPU)", "scan", verification["prepare_cpu_ms_per_scan"]);
        PrintRow("coarse images (CPU)", "query",
                 verification["coarse_images_ms_per_query"]["thread_cpu"]);
        PrintRow("verify (CPU)", "candidate pair",
                 verification["verify_ms_per_pair"]["thread_cpu"]);
        const std::string verified =
            "top " + std::to_string(verification.value("top_k", 0)) +
            (verification.value("stop_at_first_loop", false) ? " until a loop" : " verified") +
            (verification.value("odometry", false) ? " (odometry)" : "");
        PrintRow("online step, " + verified, "scan", verification["online_step_ms_per_scan"]);
        if (verification["online_rate_hz"].is_number()) {
            online_ms = verification["online_step_ms_per_scan"]["median"].get<double>();
            std::printf(
                "\nonline step: %s per scan on one core = %.1f Hz (describe, find and order the "
                "candidates, prepare, coarse images and the %s, over %d scans with candidates; "
                "file reading excluded)\n",
                Duration(online_ms).c_str(), verification["online_rate_hz"].get<double>(),
                verified.c_str(), verification.value("queries", 0));
        } else {
            std::printf(
                "\nonline step: not measured: no scan had candidates (a dataset shorter than "
                "the gap)\n");
        }
        if (const auto& bytes = verification["bytes_per_prepared_scan"]["median"];
            bytes.is_number()) {
            std::printf("memory: %.0f bytes per prepared scan (median)\n", bytes.get<double>());
        }
    } else {
        const nlohmann::json& retrieval =
            queries.contains("index_us") ? queries["index_us"] : queries["brute_force_us"];
        if (retrieval["median"].is_number()) {
            online_ms = figures["describe_ms_per_scan"].value("median", 0.0) +
                        retrieval["median"].get<double>() / 1e3;
            std::printf("\nonline step without verification: %s per scan on one core\n",
                        Duration(online_ms).c_str());
        } else {
            std::printf("\nonline step without verification: not measured (no query timed)\n");
        }
    }
    // Timed on the first scans of a long sequence (app::RunBench).
    const auto matrix_scans = figures.value("similarity_matrix_scans", std::size_t{0});
    std::string of_scans;
    if (matrix_scans < figures.value("scans", std::size_t{0}))
        of_scans = " (a matrix of the first " + std::to_string(matrix_scans) + " scans)";
    std::printf("similarity matrix: %.1f ns per comparison on one core%s\n",
                figures.value("ns_per_comparison_one_core", 0.0), of_scans.c_str());
    std::printf("peak memory: %.1f MiB\n", figures.value("peak_memory_mib", 0.0));
}

void RunBench(BenchFlags& flags) {
    ProgressPrinter progress(flags.quiet);
    flags.request.config = flags.descriptor.Resolve();
    flags.options.ApplyTo({&flags.request.config});
    flags.request.progress = progress.Callback();
    flags.request.odometry_file = flags.odometry.file();
    flags.request.odometry_topic = flags.odometry.topic();
    flags.request.odometry_calib = flags.odometry.calib();
    std::vector<std::filesystem::path> inputs = flags.dataset.Inputs();
    for (const auto& input : flags.odometry.Inputs()) inputs.push_back(input);
    inputs.emplace_back(flags.descriptor.config_file());
    // The file is checked before the run, so that a refused --json costs no measurement.
    const bool json_to_stdout = flags.json == "-";
    const bool json_given = flags.json_option->count() > 0;
    if (json_given && !json_to_stdout) app::CheckOutputFile(flags.json, inputs, flags.overwrite);
    const nlohmann::json figures = app::RunBench(flags.dataset.Open(), flags.request);
    if (json_to_stdout) {
        std::cout << figures.dump(2) << "\n";
        return;
    }
    std::cout.flush();
    PrintSummary(figures);
    if (json_given) app::WriteOutputJson(flags.json, figures, inputs, flags.overwrite);
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
    command->add_option("--matrix-scans", flags->request.matrix_scans,
                        "time the similarity matrix on at most this many scans, the first "
                        "(default " +
                            std::to_string(app::BenchRequest{}.matrix_scans) +
                            "; its memory grows with the square)");
    flags->options.AddTo(*command, app::RunCommand::kBench);
    flags->odometry.AddTo(*command,
                          "the timed queries then keep only the scans within its reach, register "
                          "the nearest views first and gate the loops, as the online detector "
                          "with a gate");
    flags->json_option = command->add_option(
        "--json", flags->json,
        "also write the figures as JSON to this file (replaced only when lidarloop wrote it "
        "and no run folder lists it, or with --overwrite); '-': JSON to stdout instead of the "
        "table");
    command->add_flag(
        "--overwrite", flags->overwrite,
        "let --json replace a file that lidarloop did not write, or one of a run's results");
    command->add_flag("--quiet", flags->quiet, "no progress bar");
    command->callback([flags] { RunBench(*flags); });
}

}  // namespace lidarloop::cli
