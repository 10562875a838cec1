// libFuzzer harness: io::ReadLoopsCsv (the loops.csv `optimise --loops` reads) on any bytes, with
// its range checks: scans of a 100-scan sequence, overlaps in [0, 1], RMSE, unit quaternions.
#include <cstddef>
#include <cstdint>

#include "fuzz_input.hpp"
#include "lidarloop/io/pose_graph_files.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto file = lidarloop::fuzz::InputFile(data, size, "loops.csv");
    lidarloop::fuzz::ExpectResultOrReadError(file, [&] { lidarloop::io::ReadLoopsCsv(file, 100); });
    return 0;
}
