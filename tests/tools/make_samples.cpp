// Writes small deterministic sample scans for the CLI tests and the setup script's first run:
// two scans of one street corner 1 m apart and one of a different courtyard, each in several
// formats. Usage: make_samples OUT_DIR [--all-formats]
//
// Points are sampled on the scene's surfaces with a density that falls off with the squared
// range, as a spinning LiDAR's does, and with 2 cm range noise. This is a fixture, not a
// simulator (that is lidarloop's `simulate` command).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>

#include "lidarloop/io/kitti_bin.hpp"
#include "lidarloop/io/osnabrueck.hpp"
#include "lidarloop/io/pcd.hpp"
#include "lidarloop/io/ply.hpp"
#include "lidarloop/io/xyz.hpp"

namespace {

using lidarloop::core::PointCloud;

struct Box {  // axis-aligned, world frame, metres
    Eigen::Vector3f min;
    Eigen::Vector3f max;
};

// Samples `count` candidate points on the ground and on the boxes' faces and keeps each with a
// probability falling with range from `sensor` (a LiDAR's beam spacing grows with range).
PointCloud SampleScene(const std::vector<Box>& boxes, const Eigen::Vector3f& sensor,
                       unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::normal_distribution<float> noise(0.0f, 0.02f);
    PointCloud cloud;
    const float ground_z = 0.0f;
    for (int i = 0; i < 400000 && cloud.size() < 6000; ++i) {
        Eigen::Vector3f p;
        const std::size_t surface = rng() % (boxes.size() + 1);
        if (surface == boxes.size()) {
            p = {sensor.x() + (unit(rng) - 0.5f) * 80.0f, sensor.y() + (unit(rng) - 0.5f) * 80.0f,
                 ground_z};
        } else {
            const Box& box = boxes[surface];
            p = box.min +
                (box.max - box.min).cwiseProduct(Eigen::Vector3f{unit(rng), unit(rng), unit(rng)});
            const int axis = static_cast<int>(rng() % 2);  // a vertical face
            p[axis] = (rng() % 2 == 0) ? box.min[axis] : box.max[axis];
        }
        const Eigen::Vector3f ray = p - sensor;
        const float range = ray.norm();
        if (range < 2.0f || range > 40.0f || unit(rng) > 4.0f / (range * range)) continue;
        cloud.push_back(p - sensor + noise(rng) * ray / range);
    }
    return cloud;
}

std::vector<Box> Corner() {
    return {{{-20, 6, 0}, {15, 14, 9}},
            {{8, -20, 0}, {16, 4, 14}},
            {{-3, -5, 0}, {-2.7f, -4.7f, 6}},
            {{2, -5, 0}, {2.3f, -4.7f, 6}},
            {{-12, -4, 0}, {-8, -2, 1.5f}}};
}

std::vector<Box> Courtyard() {
    return {{{-25, 12, 0}, {25, 20, 4}},
            {{-25, -20, 0}, {25, -12, 4}},
            {{-25, -12, 0}, {-18, 12, 4}},
            {{5, 2, 0}, {5.5f, 2.5f, 2}},
            {{-6, -7, 0}, {-1, -5, 1.2f}}};
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: make_samples OUT_DIR [--all-formats]\n");
        return 2;
    }
    namespace io = lidarloop::io;
    const std::filesystem::path out = argv[1];
    const bool all_formats = argc > 2 && std::string(argv[2]) == "--all-formats";
    std::filesystem::create_directories(out);
    const Eigen::Vector3f sensor_height(0, 0, 1.7f);
    const PointCloud corner_a = SampleScene(Corner(), sensor_height, 1);
    const PointCloud corner_b = SampleScene(Corner(), Eigen::Vector3f(1, 0, 0) + sensor_height, 2);
    const PointCloud courtyard = SampleScene(Courtyard(), sensor_height, 3);
    io::WritePcd(out / "corner_a.pcd", corner_a, io::PcdEncoding::kBinaryCompressed);
    io::WritePly(out / "corner_b.ply", corner_b, io::PlyEncoding::kBinaryLittleEndian,
                 io::PlyScalar::kFloat32);
    io::WriteKittiBin(out / "courtyard.bin", courtyard);
    if (all_formats) {
        io::WriteKittiBin(out / "corner_a.bin", corner_a);
        io::WritePcd(out / "corner_a_ascii.pcd", corner_a, io::PcdEncoding::kAscii);
        io::WritePcd(out / "corner_a_binary.pcd", corner_a, io::PcdEncoding::kBinary);
        io::WritePly(out / "corner_a_ascii.ply", corner_a, io::PlyEncoding::kAscii,
                     io::PlyScalar::kFloat32);
        io::WritePly(out / "corner_a_le64.ply", corner_a, io::PlyEncoding::kBinaryLittleEndian,
                     io::PlyScalar::kFloat64);
        io::WritePly(out / "corner_a_be.ply", corner_a, io::PlyEncoding::kBinaryBigEndian,
                     io::PlyScalar::kFloat32);
        io::WriteXyz(out / "corner_a.xyz", corner_a);
        io::WriteOsnabrueck3d(out / "scan000.3d", corner_a);
    }
    return 0;
}
