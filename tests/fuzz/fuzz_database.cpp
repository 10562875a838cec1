// libFuzzer harness: io::LoadStoredDatabase (.lldb, a saved map) on any bytes.
#include <cstddef>
#include <cstdint>

#include "fuzz_input.hpp"
#include "lidarloop/io/database_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto file = lidarloop::fuzz::InputFile(data, size, "map.lldb");
    lidarloop::fuzz::ExpectResultOrReadError(file,
                                             [&] { lidarloop::io::LoadStoredDatabase(file); });
    return 0;
}
