#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "lidarloop/app/verification_run.hpp"
#include "lidarloop/io/config_yaml.hpp"

namespace lidarloop::cli {
namespace {

struct VerifyFlags {
    std::vector<std::string> scans;
    std::string config_file;
};

void RunVerify(const VerifyFlags& flags) {
    io::RunConfig config;
    if (!flags.config_file.empty()) config = io::LoadConfigYaml(flags.config_file, config);
    const app::PairVerification result =
        app::VerifyScanFiles(flags.scans[0], flags.scans[1], config.detection.verification);
    nlohmann::json json = app::VerificationJson(result.verdict);
    json["query"] = flags.scans[0];
    json["match"] = flags.scans[1];
    json["points"] = {{"query", result.query_points}, {"match", result.match_points}};
    json["time_ms"] = {{"prepare_both", result.prepare_ms}, {"verify", result.verify_ms}};
    std::cout << json.dump(2) << "\n";
}

}  // namespace

void AddVerifyCommand(CLI::App& app) {
    auto* command = app.add_subcommand(
        "verify",
        "Register QUERY_SCAN to MATCH_SCAN without a prior pose and print the verdict as JSON "
        "(accepted, T_match_query, overlap, rmse_m, reason)");
    auto flags = std::make_shared<VerifyFlags>();
    command
        ->add_option("QUERY_SCAN MATCH_SCAN", flags->scans,
                     "two scan files, or scans of a ROS 1 bag as BAG:TOPIC:INDEX")
        ->required()
        ->expected(2);
    command
        ->add_option("--config", flags->config_file,
                     "YAML file overriding the defaults it names (section verification)")
        ->check(CLI::ExistingFile);
    command->callback([flags] { RunVerify(*flags); });
}

}  // namespace lidarloop::cli
