// libFuzzer harness: io::ReadPcd (ascii, binary, binary_compressed) on any bytes.
#include <cstddef>
#include <cstdint>

#include "fuzz_input.hpp"
#include "lidarloop/io/pcd.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto file = lidarloop::fuzz::InputFile(data, size, "scan.pcd");
    lidarloop::fuzz::ExpectResultOrReadError(file, [&] { lidarloop::io::ReadPcd(file); });
    return 0;
}
