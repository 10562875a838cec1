// libFuzzer harness: io::LoadPreparedScans (database.scans, the prepared scans that a map's
// `detect --map` verifies against) on any bytes.
#include <cstddef>
#include <cstdint>

#include "fuzz_input.hpp"
#include "lidarloop/io/prepared_scans_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto file = lidarloop::fuzz::InputFile(data, size, "database.scans");
    lidarloop::fuzz::ExpectResultOrReadError(file, [&] { lidarloop::io::LoadPreparedScans(file); });
    return 0;
}
