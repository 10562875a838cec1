#include <exception>
#include <iostream>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "lidarloop/core/error.hpp"
#include "run_output.hpp"

int main(int argc, char** argv) {
    lidarloop::cli::InstallInterruptHandler(argc, argv);  // first: before any other thread
    CLI::App app{"lidarloop: loop closure detection in sequences of 3-D LiDAR scans"};
    app.set_version_flag("--version", std::string("lidarloop ") + LIDARLOOP_VERSION);
    app.require_subcommand(1);
    lidarloop::cli::AddBagInfoCommand(app);
    lidarloop::cli::AddDemoCommand(app);
    lidarloop::cli::AddDescribeCommand(app);
    lidarloop::cli::AddDetectCommand(app);
    lidarloop::cli::AddEvaluateCommand(app);
    lidarloop::cli::AddOptimiseCommand(app);
    lidarloop::cli::AddMapCommand(app);
    lidarloop::cli::AddDistanceCommand(app);
    lidarloop::cli::AddDumpConfigCommand(app);
    lidarloop::cli::AddBenchCommand(app);
    lidarloop::cli::AddSimulateCommand(app);
    lidarloop::cli::AddVerifyCommand(app);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ValidationError& e) {
        // A value that fails its check (a missing input file, a folder given for a file, a name
        // not in the list) is an input error like any other: one line and exit code 1, not
        // CLI11's 105 (docs/cli.md, "Errors").
        std::cerr << "lidarloop: error: " << e.what() << "\n";
        return 1;
    } catch (const CLI::ParseError& e) {
        // --help and --version exit 0; a bad command line prints CLI11's message and exits 1.
        return app.exit(e) == 0 ? 0 : 1;
    } catch (const lidarloop::core::Error& e) {
        std::cerr << "lidarloop: error: " << e.what() << "\n";
        return 1;
    } catch (const std::exception& e) {
        std::cerr << "lidarloop: internal error: " << e.what() << "\n";
        return 2;
    }
    return 0;
}
