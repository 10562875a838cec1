// libFuzzer harness: io::ReadXyz (.xyz, .txt, .pts text points) on any bytes.
#include <cstddef>
#include <cstdint>

#include "fuzz_input.hpp"
#include "lidarloop/io/xyz.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto file = lidarloop::fuzz::InputFile(data, size, "scan.xyz");
    lidarloop::fuzz::ExpectResultOrReadError(file, [&] { lidarloop::io::ReadXyz(file); });
    return 0;
}
