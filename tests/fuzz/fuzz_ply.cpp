// libFuzzer harness: io::ReadPly (ascii, binary little and big endian) on any bytes.
#include <cstddef>
#include <cstdint>

#include "fuzz_input.hpp"
#include "lidarloop/io/ply.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto file = lidarloop::fuzz::InputFile(data, size, "scan.ply");
    lidarloop::fuzz::ExpectResultOrReadError(file, [&] { lidarloop::io::ReadPly(file); });
    return 0;
}
