// libFuzzer harness: io::ReadResultsCsv (another detector's query,match,distance CSV) on any bytes.
#include <cstddef>
#include <cstdint>

#include "fuzz_input.hpp"
#include "lidarloop/io/results_csv.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto file = lidarloop::fuzz::InputFile(data, size, "results.csv");
    lidarloop::fuzz::ExpectResultOrReadError(file, [&] { lidarloop::io::ReadResultsCsv(file); });
    return 0;
}
