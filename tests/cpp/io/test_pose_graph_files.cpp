#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "io_test_utils.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/io/pose_graph_files.hpp"
#include "lidarloop/io/poses.hpp"
#include "lidarloop/posegraph/pose_graph.hpp"

namespace lidarloop::io {
namespace {

using test::Contains;
using test::ReadErrorOf;
using test::TempDir;
using test::WriteFile;

// The header `lidarloop detect` writes with verification (app::WriteLoopsCsv).
const std::string kHeader =
    "query,match,distance,second_ratio,accepted,rank,tx,ty,tz,qx,qy,qz,qw,overlap_query,"
    "overlap_match,rmse_m,shifted_overlap,reason\n";

TEST(ReadLoopsCsv, ReadsTheAcceptedRowsOfDetect) {
    TempDir dir;
    const double s = std::sqrt(0.5);
    WriteFile(dir / "loops.csv", kHeader + "40,3,0.004,0.5,1,1,1.5,-2,0.25,0,0," +
                                     std::to_string(s) + "," + std::to_string(s) +
                                     ",0.6,0.4,0.12,0.9,none\n" +
                                     "41,4,0.009,,0,1,,,,,,,,,,,,pruned\n" +
                                     "42,5,0.003,0.7,1,2,0,0,0,0,0,0,1,0.8,0.7,0.05,,none\n");
    const std::vector<LoopRow> rows = ReadLoopsCsv(dir / "loops.csv", 50);
    ASSERT_EQ(rows.size(), 2u);
    EXPECT_EQ(rows[0].loop.query, 40u);
    EXPECT_EQ(rows[0].loop.match, 3u);
    EXPECT_EQ(rows[0].line, 2u);
    EXPECT_TRUE(rows[0].loop.T_match_query.translation().isApprox(Eigen::Vector3d(1.5, -2, 0.25)));
    const Eigen::Vector3d x = rows[0].loop.T_match_query.linear() * Eigen::Vector3d::UnitX();
    EXPECT_TRUE(x.isApprox(Eigen::Vector3d::UnitY(), 1e-6));  // 90 degrees about z
    EXPECT_DOUBLE_EQ(rows[0].loop.overlap, 0.4);
    EXPECT_DOUBLE_EQ(rows[0].loop.rmse_m, 0.12);
    EXPECT_EQ(rows[1].loop.query, 42u);
    EXPECT_EQ(rows[1].line, 4u);
}

TEST(ReadLoopsCsv, BadInputNamesTheFileAndLine) {
    TempDir dir;
    const auto file = dir / "loops.csv";
    const auto error = [&](const std::string& text) {
        WriteFile(file, text);
        return ReadErrorOf([&] { ReadLoopsCsv(file, 50); });
    };
    const std::string row = "40,3,0.004,0.5,1,1,1,2,0,0,0,0,1,0.6,0.4,0.1,,none\n";
    EXPECT_TRUE(Contains(error(kHeader + "60" + row.substr(2)),
                         "line 2: query scan 60 does not exist (the dataset has 50 scans)"));
    EXPECT_TRUE(Contains(error(kHeader + "40,77" + row.substr(4)), "line 2: match scan 77"));
    EXPECT_TRUE(Contains(error(kHeader + "40,3,0.004,0.5,1,1,nan,2,0,0,0,0,1,0.6,0.4,0.1,,none\n"),
                         "line 2: tx 'nan' is not a finite number"));
    EXPECT_TRUE(Contains(error(kHeader + "40,3,0.004,0.5,1,1,1,2,0,0,0,0,3,0.6,0.4,0.1,,none\n"),
                         "line 2: quaternion (qx qy qz qw) has norm 3"));
    EXPECT_TRUE(Contains(error("query,match,distance,second_ratio,accepted\n40,3,0.1,,1\n"),
                         "line 1: the header has no loop pose"));
    EXPECT_TRUE(Contains(error(kHeader + "40,3\n"), "line 2: expected 18 fields"));
    EXPECT_TRUE(Contains(error(kHeader + "40,3,0.004,,1\n"), "line 2: an accepted loop without"));
    EXPECT_TRUE(Contains(error(kHeader + "40,3,0.004,,0\n" + row), "no ReadError"));
    EXPECT_TRUE(Contains(error(kHeader + row.substr(0, row.size() - 1) + ",x\n"),
                         "line 2: expected 18 fields"));
    EXPECT_TRUE(Contains(error(""), "the file is empty"));
    EXPECT_TRUE(Contains(error(kHeader + row), "no ReadError"));
    EXPECT_TRUE(Contains(ReadErrorOf([&] { ReadLoopsCsv(dir / "missing.csv", 5); }),
                         "missing.csv: no such file"));
}

// Values out of their range are errors naming the line (issue 25, item 8).
TEST(ReadLoopsCsv, ImplausibleValuesNameTheLine) {
    TempDir dir;
    const auto file = dir / "loops.csv";
    // The full header of detect, with the distinctive fractions.
    const std::string header =
        "query,match,distance,second_ratio,accepted,rank,tx,ty,tz,qx,qy,qz,qw,overlap_query,"
        "overlap_match,distinctive_query,distinctive_match,rmse_m,shifted_overlap,reason\n";
    const auto row = [](const std::string& pose, const std::string& fit) {
        return "40,3,0.004,0.5,1,1," + pose + "," + fit + ",,none\n";
    };
    const auto error = [&](const std::string& text) {
        WriteFile(file, header + "41,4,0.004,,0\n" + text);
        return ReadErrorOf([&] { ReadLoopsCsv(file, 50); });
    };
    const std::string pose = "1,2,0,0,0,0,1";
    EXPECT_TRUE(Contains(error(row(pose, "0.6,0.4,0.3,0.2,0.1")), "no ReadError"));
    EXPECT_TRUE(Contains(error(row(pose, ",,,,")), "no ReadError"));  // unknown: NaN
    EXPECT_TRUE(Contains(error(row(pose, "-5,0.4,0.3,0.2,0.1")),
                         "loops.csv: line 3: overlap_query '-5' is outside [0, 1]"));
    EXPECT_TRUE(Contains(error(row(pose, "0.6,1.5,0.3,0.2,0.1")),
                         "line 3: overlap_match '1.5' is outside [0, 1]"));
    EXPECT_TRUE(Contains(error(row(pose, "0.6,0.4,-0.1,0.2,0.1")),
                         "line 3: distinctive_query '-0.1' is outside [0, 1]"));
    EXPECT_TRUE(Contains(error(row(pose, "0.6,0.4,0.3,2,0.1")),
                         "line 3: distinctive_match '2' is outside [0, 1]"));
    EXPECT_TRUE(Contains(error(row(pose, "0.6,0.4,0.3,0.2,-1")),
                         "line 3: rmse_m '-1' is outside [0, 100]"));
    EXPECT_TRUE(Contains(error(row(pose, "0.6,0.4,0.3,0.2,1e300")),
                         "line 3: rmse_m '1e300' is outside [0, 100]"));
    EXPECT_TRUE(Contains(error(row(pose, "0.6,0.4,0.3,0.2,inf")),
                         "line 3: rmse_m 'inf' is not a finite number"));
    EXPECT_TRUE(Contains(error(row("1,2,0,0,0,0,1.01", "0.6,0.4,0.3,0.2,0.1")),
                         "line 3: quaternion (qx qy qz qw) has norm 1.01, expected 1"));
    EXPECT_TRUE(Contains(error(row("1,2,0,0,0,0,1.0001", "0.6,0.4,0.3,0.2,0.1")), "no ReadError"));
    EXPECT_TRUE(Contains(error(row("1e300,2,0,0,0,0,1", "0.6,0.4,0.3,0.2,0.1")),
                         "line 3: the loop's translation (tx ty tz) is 1e+300 m long"));
}

// A plain g2o reader for the round trip: vertices and edges by their tags.
struct G2oFile {
    std::vector<std::vector<double>> vertices;  // id x y z qx qy qz qw
    std::vector<std::vector<double>> edges;     // from to x y z qx qy qz qw + 21
    std::vector<std::string> other;
};

G2oFile ParseG2o(const std::string& text) {
    G2oFile g2o;
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream fields(line);
        std::string tag;
        fields >> tag;
        std::vector<double> values;
        double v = 0.0;
        while (fields >> v) values.push_back(v);
        if (tag == "VERTEX_SE3:QUAT")
            g2o.vertices.push_back(values);
        else if (tag == "EDGE_SE3:QUAT")
            g2o.edges.push_back(values);
        else
            g2o.other.push_back(line);
    }
    return g2o;
}

TEST(WriteG2o, WritesVerticesEdgesAndTheUpperTriangleOfTheInformation) {
    TempDir dir;
    core::Transform a = core::Transform::Identity();
    core::Transform b = core::Transform::Identity();
    b.rotate(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()));
    b.translation() = Eigen::Vector3d(1.25, -3, 0.5);
    posegraph::Edge edge;
    edge.from = 0;
    edge.to = 1;
    edge.T_from_to = b;
    for (int r = 0; r < 6; ++r)
        for (int c = 0; c < 6; ++c) edge.information(r, c) = r == c ? 100 + r : (r + 1) * (c + 1);
    posegraph::Edge rejected = edge;
    rejected.from = 1;
    rejected.to = 0;
    WriteG2o(dir / "graph.g2o", {a, b}, {edge}, {rejected});
    const G2oFile g2o = ParseG2o(test::ReadFile(dir / "graph.g2o"));
    ASSERT_EQ(g2o.vertices.size(), 2u);
    ASSERT_EQ(g2o.edges.size(), 1u);
    const Eigen::Quaterniond q = Eigen::Quaterniond(b.linear()).normalized();
    const std::vector<double> vertex = {1, 1.25, -3, 0.5, q.x(), q.y(), q.z(), q.w()};
    for (std::size_t k = 0; k < vertex.size(); ++k) EXPECT_EQ(g2o.vertices[1][k], vertex[k]) << k;
    ASSERT_EQ(g2o.edges[0].size(), 2u + 7u + 21u);
    EXPECT_EQ(g2o.edges[0][2], 1.25);
    EXPECT_EQ(g2o.edges[0][8], q.w());
    // Upper triangle row by row: (0,0) (0,1) ... (0,5) (1,1) ...
    EXPECT_EQ(g2o.edges[0][9], 100);
    EXPECT_EQ(g2o.edges[0][10], 2);    // (0,1)
    EXPECT_EQ(g2o.edges[0][15], 101);  // (1,1)
    EXPECT_EQ(g2o.edges[0][29], 105);  // (5,5)
    ASSERT_EQ(g2o.other.size(), 3u);   // header comment, FIX 0, the rejected edge
    EXPECT_EQ(g2o.other[1], "FIX 0");
    EXPECT_EQ(g2o.other[2].rfind("# rejected EDGE_SE3:QUAT 1 0 ", 0), 0u);
    // An edge to a vertex the file does not hold (g2o would add it as a free pose) is refused.
    EXPECT_THROW(WriteG2o(dir / "short.g2o", {a}, {edge}), core::ConfigError);
    EXPECT_THROW(WriteG2o(dir / "short.g2o", {a}, {}, {rejected}), core::ConfigError);
    EXPECT_FALSE(std::filesystem::exists(dir / "short.g2o"));
}

TEST(ReadPoses, TellsKittiFromTum) {
    TempDir dir;
    WriteFile(dir / "kitti.txt", "# c\n1 0 0 5 0 1 0 6 0 0 1 7\n");
    WriteFile(dir / "tum.txt", "0.5 5 6 7 0 0 0 1\n");
    WriteFile(dir / "bad.txt", "1 2 3\n");
    EXPECT_EQ(ReadPoses(dir / "kitti.txt").at(0).T_world_sensor.translation().x(), 5.0);
    EXPECT_EQ(ReadPoses(dir / "tum.txt").at(0).time_s, 0.5);
    EXPECT_TRUE(Contains(ReadErrorOf([&] { ReadPoses(dir / "bad.txt"); }),
                         "line 1: cannot tell the pose format"));
}

}  // namespace
}  // namespace lidarloop::io
