// libFuzzer harness: the Osnabrück pose readers (.pose and .frames) on the same bytes.
#include <cstddef>
#include <cstdint>

#include "fuzz_input.hpp"
#include "lidarloop/io/osnabrueck.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace lidarloop;
    const auto pose = fuzz::InputFile(data, size, "scan000.pose");
    fuzz::ExpectResultOrReadError(pose, [&] { io::ReadOsnabrueckPose(pose); });
    const auto frames = fuzz::InputFile(data, size, "scan000.frames");
    fuzz::ExpectResultOrReadError(frames, [&] { io::ReadOsnabrueckFrames(frames); });
    return 0;
}
