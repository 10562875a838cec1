// libFuzzer harness: the pose readers on the same bytes: KITTI poses.txt, TUM, KITTI calib.txt, and
// KITTI times.txt beside a valid poses.txt of two poses.
#include <cstddef>
#include <cstdint>

#include "fuzz_input.hpp"
#include "lidarloop/io/poses.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace lidarloop;
    const auto file = fuzz::InputFile(data, size, "poses.txt");
    fuzz::ExpectResultOrReadError(file, [&] { io::ReadKittiPoses(file); });
    fuzz::ExpectResultOrReadError(file, [&] { io::ReadTumPoses(file); });
    fuzz::ExpectResultOrReadError(file, [&] { io::ReadKittiCalibTr(file); });
    static const char kTwoPoses[] = "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n";
    const auto poses = fuzz::InputFile(reinterpret_cast<const std::uint8_t*>(kTwoPoses),
                                       sizeof(kTwoPoses) - 1, "two_poses.txt");
    const auto times = fuzz::InputFile(data, size, "times.txt");
    fuzz::ExpectResultOrReadError(
        times, [&] { io::ReadKittiPoses(poses, core::Transform::Identity(), times); });
    return 0;
}
