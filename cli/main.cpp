#include <exception>
#include <iostream>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "lidarloop/app/heap_reuse.hpp"
#include "lidarloop/core/error.hpp"
#include "run_output.hpp"

namespace {

// How a command ends: its message on stderr and its exit code, unless an interrupt is being
// handled, whose exit code (128 + the signal) and message are the ones the user must see.
int End(const std::string& message, int code) {
    if (lidarloop::cli::InterruptReceived()) lidarloop::cli::AwaitInterruptExit();
    if (!message.empty()) std::cerr << message << "\n";
    return code;
}

// CLI11 2.1 reads "-1" into an unsigned flag as 2^64 - 1 (a bench that never ends, a seed that
// is not the one asked for): every unsigned flag of every command refuses a negative number.
void RefuseNegativeUnsigned(CLI::App& app) {
    const CLI::Validator non_negative(
        [](const std::string& value) {
            const auto first = value.find_first_not_of(" \t");
            return first != std::string::npos && value[first] == '-'
                       ? "must not be negative, got " + value
                       : std::string();
        },
        "");
    for (CLI::Option* option : app.get_options()) {
        if (option->get_type_name() == "UINT") option->check(non_negative);
    }
    for (CLI::App* command : app.get_subcommands([](CLI::App*) { return true; }))
        RefuseNegativeUnsigned(*command);
}

}  // namespace

int main(int argc, char** argv) {
    lidarloop::cli::InstallInterruptHandler(argc, argv);  // first: before any other thread
    lidarloop::app::KeepFreedMemoryForReuse();            // before any scan is read
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
    RefuseNegativeUnsigned(app);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ValidationError& e) {
        // A value that fails its check (a missing input file, a folder given for a file, a name
        // not in the list) is an input error like any other: one line and exit code 1, not
        // CLI11's 105 (docs/cli.md, "Errors").
        return End(std::string("lidarloop: error: ") + e.what(), 1);
    } catch (const CLI::ParseError& e) {
        // --help and --version exit 0; a bad command line prints CLI11's message and exits 1.
        return app.exit(e) == 0 ? 0 : 1;
    } catch (const lidarloop::core::Error& e) {
        return End(std::string("lidarloop: error: ") + e.what(), 1);
    } catch (const std::exception& e) {
        return End(std::string("lidarloop: internal error: ") + e.what(), 2);
    }
    return End("", 0);
}
