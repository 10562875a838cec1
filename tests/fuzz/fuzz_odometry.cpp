// libFuzzer harness: io::ReadPoses as `optimise --odometry` calls it (KITTI or TUM told apart by
// the first line, a step bound of 100 m between consecutive poses, times that must increase),
// and as the ground truth of a dataset without the bound, on the same bytes.
#include <cstddef>
#include <cstdint>

#include "fuzz_input.hpp"
#include "lidarloop/io/poses.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace lidarloop;
    const auto file = fuzz::InputFile(data, size, "odometry.txt");
    fuzz::ExpectResultOrReadError(
        file, [&] { io::ReadPoses(file, core::Transform::Identity(), {}, 100.0); });
    fuzz::ExpectResultOrReadError(file, [&] { io::ReadPoses(file); });
    return 0;
}
