// Writes test::SmallSequence into FOLDER for ctest's app_tests.small_sequence fixture: the
// run-layer tests copy it instead of each simulating the same 200 scans.
#include <unistd.h>

#include <exception>
#include <filesystem>
#include <iostream>
#include <string>

#include "app/app_test_utils.hpp"

int main(int argc, char** argv) {
    if (argc != 2) {
        std::cerr << "usage: write_small_sequence FOLDER\n";
        return 2;
    }
    try {
        const std::filesystem::path folder = argv[1];
        // Written beside, then renamed: a test never copies a half-written sequence. Two ctest
        // runs must not share a build folder (this one replaces the other's sequence).
        const std::filesystem::path partial =
            folder.string() + ".partial." + std::to_string(::getpid());
        std::filesystem::remove_all(partial);
        lidarloop::test::WriteSmallSequence(partial);
        std::filesystem::remove_all(folder);
        std::filesystem::rename(partial, folder);
    } catch (const std::exception& e) {
        std::cerr << "write_small_sequence: " << e.what() << '\n';
        return 1;
    }
    return 0;
}
