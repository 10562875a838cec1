#include "run_output.hpp"

#include <pthread.h>
#include <signal.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>

namespace lidarloop::cli {
namespace {

std::string command_line;
std::string command_name;
std::atomic<bool> interrupt_received{false};

sigset_t InterruptSignals() {
    sigset_t signals;
    sigemptyset(&signals);
    sigaddset(&signals, SIGINT);
    sigaddset(&signals, SIGTERM);
    return signals;
}

[[noreturn]] void WatchInterrupts(sigset_t signals) {
    int signal = 0;
    while (sigwait(&signals, &signal) != 0) {
    }
    interrupt_received = true;  // before the staging folder goes: see InterruptReceived
    const std::filesystem::path folder = app::AbandonActiveRun(
        app::RunStatus::kInterrupted, "interrupted by signal " + std::to_string(signal));
    if (!folder.empty()) {
        std::fprintf(stderr,
                     "\nlidarloop: interrupted; nothing of this run was kept in %s (earlier "
                     "results there stay as they were)\n",
                     folder.c_str());
    } else {
        std::fprintf(stderr, "\nlidarloop: interrupted\n");
    }
    std::_Exit(128 + signal);
}

}  // namespace

void InstallInterruptHandler(int argc, char** argv) {
    for (int a = 0; a < argc; ++a) command_line += (a > 0 ? " " : "") + std::string(argv[a]);
    // The first word that is no flag: lidarloop has no global option that takes a value.
    for (int a = 1; a < argc && command_name.empty(); ++a) {
        if (argv[a][0] != '-') command_name = argv[a];
    }
    const sigset_t signals = InterruptSignals();
    // Blocked here, before any thread starts, so every later thread (oneTBB's workers) inherits
    // the mask and only the watcher receives them.
    pthread_sigmask(SIG_BLOCK, &signals, nullptr);
    std::thread(WatchInterrupts, signals).detach();
}

const std::string& CommandLine() { return command_line; }

const std::string& CommandName() { return command_name; }

bool InterruptReceived() { return interrupt_received; }

void AwaitInterruptExit() {
    for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));
}

}  // namespace lidarloop::cli
