#include "lidarloop/io/kitti_sequence.hpp"

#include <cstdio>
#include <string>
#include <system_error>

#include "lidarloop/io/detail/text_parsing.hpp"
#include "lidarloop/io/kitti_bin.hpp"
#include "lidarloop/io/read_error.hpp"

namespace lidarloop::io {
namespace fs = std::filesystem;
namespace {

std::string PoseLine(const core::StampedPose& pose) {
    std::string text;
    const Eigen::Matrix<double, 3, 4> M = pose.T_world_sensor.matrix().topRows<3>();
    for (int row = 0; row < 3; ++row) {
        for (int col = 0; col < 4; ++col) {
            detail::AppendNumber(text, M(row, col), row == 2 && col == 3 ? '\n' : ' ');
        }
    }
    return text;
}

void ClearOldScans(const fs::path& velodyne, bool overwrite) {
    std::error_code ec;
    std::size_t old_scans = 0;
    for (const auto& entry : fs::directory_iterator(velodyne, ec)) {
        if (entry.path().extension() != ".bin") continue;
        if (overwrite) {
            fs::remove(entry.path(), ec);
            if (ec) throw WriteError(entry.path(), "cannot delete (" + ec.message() + ")");
        }
        ++old_scans;
    }
    if (ec) throw WriteError(velodyne, "cannot list (" + ec.message() + ")");
    if (old_scans > 0 && !overwrite) {
        throw WriteError(velodyne, "already holds " + std::to_string(old_scans) +
                                       " .bin scans; choose an empty folder or overwrite");
    }
}

}  // namespace

KittiSequenceWriter::KittiSequenceWriter(const fs::path& dir, bool overwrite) : dir_(dir) {
    std::error_code ec;
    fs::create_directories(dir_ / "velodyne", ec);
    if (ec) throw WriteError(dir_ / "velodyne", "cannot create (" + ec.message() + ")");
    ClearOldScans(dir_ / "velodyne", overwrite);
    poses_out_ = detail::OpenForWriting(dir_ / "poses.txt", /*binary=*/false);
    times_out_ = detail::OpenForWriting(dir_ / "times.txt", /*binary=*/false);
    fs::remove(dir_ / "poses_odometry.txt", ec);  // a stale one would not match the new poses
}

fs::path KittiSequenceWriter::ScanPath(std::size_t index) const {
    char name[32];
    std::snprintf(name, sizeof(name), "%06zu.bin", index);
    return dir_ / "velodyne" / name;
}

void KittiSequenceWriter::WriteScan(std::size_t index, const core::PointCloud& cloud) const {
    WriteKittiBin(ScanPath(index), cloud);
}

void KittiSequenceWriter::AppendPose(const core::StampedPose& ground_truth) {
    poses_out_ << PoseLine(ground_truth);
    std::string time;
    detail::AppendNumber(time, ground_truth.time_s, '\n');
    times_out_ << time;
    ++poses_;
}

void KittiSequenceWriter::AppendOdometryPose(const core::StampedPose& odometry) {
    if (!odometry_out_.is_open()) {
        odometry_out_ = detail::OpenForWriting(dir_ / "poses_odometry.txt", /*binary=*/false);
    }
    odometry_out_ << PoseLine(odometry);
    ++odometry_poses_;
}

void KittiSequenceWriter::Finish() {
    const auto close = [](std::ofstream& out, const fs::path& file) {
        if (!out.is_open()) return;
        out.close();
        if (!out) throw WriteError(file, "writing failed");
    };
    close(poses_out_, dir_ / "poses.txt");
    close(times_out_, dir_ / "times.txt");
    close(odometry_out_, dir_ / "poses_odometry.txt");
    if (odometry_poses_ != 0 && odometry_poses_ != poses_) {
        throw WriteError(dir_ / "poses_odometry.txt", "holds " + std::to_string(odometry_poses_) +
                                                          " poses for " + std::to_string(poses_) +
                                                          " scans");
    }
}

}  // namespace lidarloop::io
