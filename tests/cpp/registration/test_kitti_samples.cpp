// Verification on real KITTI HDL-64E scans (../shared/data/kitti-samples, never copied into the
// repository; skipped with a message when absent). Ground truth and how far to trust it: the
// folder's README.md.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "lidarloop/io/kitti_bin.hpp"
#include "lidarloop/registration/neighbor_grid.hpp"
#include "lidarloop/registration/point_tree.hpp"
#include "lidarloop/registration/verification.hpp"
#include "registration_test_utils.hpp"

namespace lidarloop::registration {
namespace {

const std::filesystem::path kSamples = LIDARLOOP_KITTI_SAMPLES_DIR;

Eigen::Matrix4d ReadRow34(std::istringstream& in) {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) in >> m(r, c);
    return m;
}

Eigen::Matrix4d Calibration(const std::string& sequence) {
    std::ifstream in(kSamples / ("calib_" + sequence + ".txt"));
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind("Tr:", 0) == 0) {
            std::istringstream values(line.substr(3));
            return ReadRow34(values);
        }
    }
    throw std::runtime_error("no Tr: line in calib_" + sequence + ".txt");
}

// T_velo0_veloi = Tr^-1 * P_i * Tr (the README's formula).
Eigen::Matrix4d LidarPose(const std::string& sequence, int frame) {
    std::ifstream in(kSamples / "poses" / (sequence + ".txt"));
    std::string line;
    for (int i = 0; i <= frame; ++i) std::getline(in, line);
    std::istringstream values(line);
    const Eigen::Matrix4d Tr = Calibration(sequence);
    return Tr.inverse() * ReadRow34(values) * Tr;
}

core::PointCloud Scan(const std::string& sequence, int frame) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.bin", frame);
    return io::ReadKittiBin(kSamples / sequence / "velodyne" / name);
}

struct Pair {
    std::string sequence;
    int match, query;
};

class KittiSamples : public ::testing::Test {
protected:
    void SetUp() override {
        if (!std::filesystem::exists(kSamples / "README.md"))
            GTEST_SKIP() << "real KITTI samples not found at " << kSamples
                         << " (see ../shared/data/kitti-samples/README.md)";
    }
    static Verification Run(const Pair& pair) {
        return VerifyPair(Scan(pair.sequence, pair.query), Scan(pair.sequence, pair.match),
                          VerificationConfig{});
    }
    static Eigen::Matrix4d Truth(const Pair& pair) {
        return LidarPose(pair.sequence, pair.match).inverse() *
               LidarPose(pair.sequence, pair.query);
    }
    static double YawDeg(const Eigen::Matrix4d& T) {
        return std::atan2(T(1, 0), T(0, 0)) * 180.0 / M_PI;
    }
};

// Both loops of sequence 08, revisited in the opposite direction: the yaw within 2 degrees and
// the planar translation within 1.5 m of the GPS/INS ground truth (its drift, README).
TEST_F(KittiSamples, TrueLoopsOf08AreAcceptedWithTheirPose) {
    for (const Pair& pair : {Pair{"08", 209, 1684}, Pair{"08", 720, 1500}}) {
        const Verification v = Run(pair);
        const Eigen::Matrix4d truth = Truth(pair);
        const Eigen::Matrix4d found = v.T_match_query.matrix();
        SCOPED_TRACE(pair.sequence + " " + std::to_string(pair.match) + " <- " +
                     std::to_string(pair.query));
        EXPECT_TRUE(v.accepted) << ToString(v.reason);
        EXPECT_LT(std::abs(std::remainder(YawDeg(found) - YawDeg(truth), 360.0)), 2.0);
        EXPECT_LT((found.block<2, 1>(0, 3) - truth.block<2, 1>(0, 3)).norm(), 1.5);
    }
}

// Consecutive scans of 00: the ground truth is accurate to centimetres there.
TEST_F(KittiSamples, ConsecutiveScansOf00MatchTheTruthToCentimetres) {
    for (const Pair& pair : {Pair{"00", 94, 95}, Pair{"00", 198, 199}}) {
        const Verification v = Run(pair);
        const Eigen::Matrix4d truth = Truth(pair);
        EXPECT_TRUE(v.accepted) << ToString(v.reason);
        EXPECT_LT((v.T_match_query.translation() - truth.block<3, 1>(0, 3)).norm(), 0.05);
        EXPECT_LT(std::abs(std::remainder(YawDeg(v.T_match_query.matrix()) - YawDeg(truth), 360.0)),
                  0.3);
    }
}

// Scans 58 m (00) and 80-100 m (08) apart: never the same place.
TEST_F(KittiSamples, DifferentPlacesAreRejected) {
    for (const Pair& pair : {Pair{"00", 94, 198}, Pair{"00", 95, 199}, Pair{"00", 94, 199},
                             Pair{"00", 95, 198}, Pair{"08", 209, 720}, Pair{"08", 209, 1500},
                             Pair{"08", 1684, 720}, Pair{"08", 1684, 1500}}) {
        const Verification v = Run(pair);
        EXPECT_FALSE(v.accepted) << pair.sequence << " " << pair.match << " <- " << pair.query
                                 << ": overlap " << v.overlap.Min();
    }
}

// ICP's thinner first stage (IcpConfig::first_stage_*_points) against the slow path it replaced,
// every point in every stage: the same decision on every pair, loops and different places, and
// an accepted pose within a centimetre and 0.05 degrees.
TEST_F(KittiSamples, TheThinnedFirstStageDecidesAsEveryPointDoes) {
    const VerificationConfig every_point = test::EveryPointInEveryStage();
    for (const Pair& pair :
         {Pair{"08", 209, 1684}, Pair{"08", 720, 1500}, Pair{"00", 94, 95}, Pair{"00", 198, 199},
          Pair{"00", 94, 198}, Pair{"08", 209, 720}, Pair{"08", 1684, 1500}}) {
        SCOPED_TRACE(pair.sequence + " " + std::to_string(pair.match) + " <- " +
                     std::to_string(pair.query));
        const core::PointCloud query = Scan(pair.sequence, pair.query);
        const core::PointCloud match = Scan(pair.sequence, pair.match);
        const Verification fast = VerifyPair(query, match, VerificationConfig{});
        const Verification slow = VerifyPair(query, match, every_point);
        EXPECT_EQ(fast.accepted, slow.accepted)
            << ToString(fast.reason) << " / " << ToString(slow.reason);
        if (!fast.accepted || !slow.accepted) continue;
        const core::Transform difference = fast.T_match_query.inverse() * slow.T_match_query;
        EXPECT_LT(difference.translation().norm(), 0.01);
        EXPECT_LT(Eigen::AngleAxisd(difference.linear()).angle() * 180.0 / M_PI, 0.05);
    }
}

// Every `stride`-th point: a 120k-point HDL-64E scan thinned towards a sparse sensor's density.
core::PointCloud Thinned(const core::PointCloud& scan, std::size_t stride) {
    core::PointCloud thin;
    for (std::size_t i = 0; i < scan.size(); i += stride) thin.push_back(scan[i]);
    return thin;
}

// The rule is density-aware (voxel centroids, fractions, roughness-relative RMSE): the same
// decisions on scans thinned to 1/4 (~30k points, a VLP-32's), 1/8 (~15k, a VLP-16's) and 1/40
// (~3k, a LIO front end's sparse keyframe).
TEST_F(KittiSamples, DecisionsHoldOnThinnedScans) {
    const Pair loops[] = {{"08", 209, 1684}, {"08", 720, 1500}, {"00", 94, 95}};
    const Pair others[] = {{"00", 94, 198}, {"08", 209, 720}, {"08", 1684, 1500}};
    for (const std::size_t stride : {4, 8, 40}) {
        SCOPED_TRACE("every " + std::to_string(stride) + "th point");
        const auto run = [&](const Pair& pair) {
            return VerifyPair(Thinned(Scan(pair.sequence, pair.query), stride),
                              Thinned(Scan(pair.sequence, pair.match), stride),
                              VerificationConfig{});
        };
        for (const Pair& pair : loops) {
            const Verification v = run(pair);
            EXPECT_TRUE(v.accepted)
                << pair.match << " <- " << pair.query << ": " << ToString(v.reason);
            EXPECT_LT(std::abs(std::remainder(
                          YawDeg(v.T_match_query.matrix()) - YawDeg(Truth(pair)), 360.0)),
                      2.0);
        }
        for (const Pair& pair : others) {
            EXPECT_FALSE(run(pair).accepted) << pair.match << " <- " << pair.query;
        }
    }
}

// The points of `scan` that `keep` selects.
template <typename Keep>
core::PointCloud Kept(const core::PointCloud& scan, Keep keep) {
    core::PointCloud kept;
    for (const Eigen::Vector3f& point : scan) {
        if (keep(point)) kept.push_back(point);
    }
    return kept;
}

double ElevationDeg(const Eigen::Vector3f& p) {
    return std::atan2(p.z(), std::hypot(p.x(), p.y())) * 180.0 / M_PI;
}

double AzimuthDeg(const Eigen::Vector3f& p) { return std::atan2(p.y(), p.x()) * 180.0 / M_PI; }

// Issue 24's bad input, cut from real scans of a true loop: one ring, every point pressed onto
// the road's plane, a 10-degree field of view, a handful of points. None can pin a loop's pose:
// each is rejected with a reason, never accepted (the full scans are, in the tests above).
TEST_F(KittiSamples, ScansThatCannotPinAPoseAreRejectedWithAReason) {
    const auto one_ring = [](const core::PointCloud& scan) {
        return Kept(scan,
                    [](const Eigen::Vector3f& p) { return std::abs(ElevationDeg(p) + 8.0) < 0.2; });
    };
    const auto on_the_road_plane = [](core::PointCloud scan) {
        for (Eigen::Vector3f& point : scan) point.z() = -1.73F;  // the sensor's height
        return scan;
    };
    const auto field_of_view = [](double centre_deg) {
        return [centre_deg](const core::PointCloud& scan) {
            return Kept(scan, [centre_deg](const Eigen::Vector3f& p) {
                return std::abs(std::remainder(AzimuthDeg(p) - centre_deg, 360.0)) < 5.0;
            });
        };
    };
    const auto handful = [](const core::PointCloud& scan) {
        return Thinned(scan, scan.size() / 30);
    };
    const std::vector<std::pair<std::string, std::function<core::PointCloud(core::PointCloud)>>>
        cuts = {{"one ring", one_ring},
                {"one plane", on_the_road_plane},
                {"10 degrees ahead", field_of_view(0.0)},
                {"10 degrees to the left", field_of_view(90.0)},
                {"10 degrees behind", field_of_view(180.0)},
                {"30 points", handful}};
    for (const Pair& pair : {Pair{"08", 209, 1684}, Pair{"08", 720, 1500}, Pair{"00", 94, 95}}) {
        const core::PointCloud query = Scan(pair.sequence, pair.query);
        const core::PointCloud match = Scan(pair.sequence, pair.match);
        for (const auto& [name, cut] : cuts) {
            SCOPED_TRACE(pair.sequence + " " + std::to_string(pair.match) + " <- " +
                         std::to_string(pair.query) + ", " + name);
            const core::PointCloud cut_query = cut(query);
            ASSERT_FALSE(cut_query.empty());
            for (const Verification& v : {VerifyPair(cut_query, cut(match), VerificationConfig{}),
                                          VerifyPair(cut_query, match, VerificationConfig{})}) {
                EXPECT_FALSE(v.accepted) << "overlap " << v.overlap.Min();
                EXPECT_NE(v.reason, RejectReason::kNone);
            }
        }
    }
}

// PrepareScan's neighbour search on real centroids: the grid finds exactly the k-d tree's
// neighbours, in the same order, for the normals (k = 10) and distinctiveness (k = 30).
TEST_F(KittiSamples, TheNeighbourGridFindsWhatTheTreeFinds) {
    for (const int frame : {209, 1684}) {
        // PrepareScan's defaults: 3-60 m, 0.5 m voxels.
        const std::vector<Eigen::Vector3f> centroids = test::VoxelCentroids(Scan("08", frame));
        ASSERT_GT(centroids.size(), 10000u);
        const PointTree tree(&centroids);
        const NeighborGrid grid(centroids, 0.5F);
        for (const int k : {10, 30}) {
            NeighborGrid::Scratch scratch;
            std::vector<std::uint32_t> from_tree, from_grid;
            std::size_t differing = 0;
            for (const Eigen::Vector3f& centroid : centroids) {
                tree.Knn(centroid, k, from_tree);
                grid.Knn(centroid, k, scratch, from_grid);
                differing += from_tree != from_grid ? 1 : 0;
            }
            EXPECT_EQ(differing, 0u) << "frame " << frame << ", k " << k;
        }
    }
}

}  // namespace
}  // namespace lidarloop::registration
