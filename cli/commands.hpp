#pragma once

#include <CLI/CLI.hpp>

namespace lidarloop::cli {

// One function per subcommand; each lives in the file of the same name.
void AddBagInfoCommand(CLI::App& app);
void AddBenchCommand(CLI::App& app);
void AddDemoCommand(CLI::App& app);
void AddDescribeCommand(CLI::App& app);
void AddDetectCommand(CLI::App& app);
void AddDistanceCommand(CLI::App& app);
void AddDumpConfigCommand(CLI::App& app);
void AddEvaluateCommand(CLI::App& app);
void AddMapCommand(CLI::App& app);
void AddOptimiseCommand(CLI::App& app);
void AddSimulateCommand(CLI::App& app);
void AddVerifyCommand(CLI::App& app);

}  // namespace lidarloop::cli
