// libFuzzer harness: io::ReadKittiBin on any bytes.
#include <cstddef>
#include <cstdint>

#include "fuzz_input.hpp"
#include "lidarloop/io/kitti_bin.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto file = lidarloop::fuzz::InputFile(data, size, "scan.bin");
    lidarloop::fuzz::ExpectResultOrReadError(file, [&] { lidarloop::io::ReadKittiBin(file); });
    return 0;
}
