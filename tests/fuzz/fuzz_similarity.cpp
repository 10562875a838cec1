// libFuzzer harness: io::ReadSimilarityMatrix (similarity.bin) on any bytes.
#include <cstddef>
#include <cstdint>

#include "fuzz_input.hpp"
#include "lidarloop/io/similarity_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto file = lidarloop::fuzz::InputFile(data, size, "similarity.bin");
    lidarloop::fuzz::ExpectResultOrReadError(file,
                                             [&] { lidarloop::io::ReadSimilarityMatrix(file); });
    return 0;
}
