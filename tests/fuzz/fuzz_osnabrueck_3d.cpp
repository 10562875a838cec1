// libFuzzer harness: io::ReadOsnabrueck3d (scanNNN.3d) on any bytes.
#include <cstddef>
#include <cstdint>

#include "fuzz_input.hpp"
#include "lidarloop/io/osnabrueck.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto file = lidarloop::fuzz::InputFile(data, size, "scan000.3d");
    lidarloop::fuzz::ExpectResultOrReadError(file, [&] { lidarloop::io::ReadOsnabrueck3d(file); });
    return 0;
}
