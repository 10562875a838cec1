#pragma once

// Shared by the harnesses of tests/fuzz: the fuzzer's bytes as a file (the readers take paths)
// and the rule every reader keeps: any bytes give a result or an io::ReadError naming the file.
// Anything else (another exception, a sanitizer report, an allocation beyond libFuzzer's
// -malloc_limit_mb) is a bug.

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "lidarloop/io/read_error.hpp"

namespace lidarloop::fuzz {

/// A folder of this process's input files, removed at a normal exit. One per process, since
/// libFuzzer's -jobs and -fork run several processes side by side. In /dev/shm where there is
/// one: rewriting a file on disk for every input made fuzzing 50 times slower (280 inputs/s
/// against 14,000 for fuzz_xyz). Folders of processes that died (a crash) are removed too.
inline const std::filesystem::path& InputFolder() {
    // Never destroyed, so that the exit handler below can still read it.
    static const std::filesystem::path* const folder = [] {
        std::error_code ec;
        const std::filesystem::path base = std::filesystem::is_directory("/dev/shm", ec)
                                               ? std::filesystem::path("/dev/shm")
                                               : std::filesystem::temp_directory_path();
        const std::string prefix = "lidarloop_fuzz_";
        for (const auto& entry : std::filesystem::directory_iterator(base, ec)) {
            const std::string name = entry.path().filename().string();
            if (name.rfind(prefix, 0) != 0) continue;
            const long pid = std::strtol(name.c_str() + prefix.size(), nullptr, 10);
            if (pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH)
                std::filesystem::remove_all(entry.path(), ec);
        }
        auto* path = new std::filesystem::path(base / (prefix + std::to_string(::getpid())));
        std::filesystem::create_directories(*path);
        return path;
    }();
    static const bool cleanup_registered = [] {
        return std::atexit([] {
                   std::error_code ignored;
                   std::filesystem::remove_all(*folder, ignored);
               }) == 0;
    }();
    (void)cleanup_registered;
    return *folder;
}

/// Writes `size` bytes at `data` to the file `name` (e.g. "scan.pcd": readers go by the
/// extension) in InputFolder() and returns its path. libFuzzer runs one input at a time, so
/// each input overwrites the last.
inline std::filesystem::path InputFile(const std::uint8_t* data, std::size_t size,
                                       const std::string& name) {
    const std::filesystem::path file = InputFolder() / name;
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    out.close();
    if (!out) {
        std::fprintf(stderr, "fuzz harness: cannot write %s\n", file.c_str());
        std::abort();
    }
    return file;
}

/// Runs `read()`, which reads `source` (a file, or the name given for text read from memory).
/// Returning or throwing an io::ReadError whose message names `source` is fine; any other
/// exception, a ReadError that does not say which file, or one longer than kMaxMessageChars
/// beside the file name (input quoted uncut, issue 25) aborts (a crash to libFuzzer).
template <typename Read>
void ExpectResultOrReadError(const std::string& source, Read&& read) {
    constexpr std::size_t kMaxMessageChars = 600;
    try {
        read();
    } catch (const io::ReadError& e) {
        const std::string_view message = e.what();
        if (message.find(source) == std::string_view::npos) {
            std::fprintf(stderr, "fuzz harness: the ReadError does not name %s: %s\n",
                         source.c_str(), e.what());
            std::abort();
        }
        if (message.size() > kMaxMessageChars + source.size()) {
            std::fprintf(stderr, "fuzz harness: a ReadError of %zu characters: %.300s...\n",
                         message.size(), e.what());
            std::abort();
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "fuzz harness: not an io::ReadError: %s\n", e.what());
        std::abort();
    }
}

}  // namespace lidarloop::fuzz
