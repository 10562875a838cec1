// Registers two KITTI .bin scans with the Open3D oracle (FPFH + RANSAC, then ICP; no prior pose)
// and prints one JSON object: T_match_query (4x4, row-major, maps query points into the match
// frame), Open3D's fitness and inlier RMSE, and the registration's wall time (reading excluded).
//
// Usage: open3d_register QUERY.bin MATCH.bin [--voxel M] [--refine-voxel M] [--max-range M]
//                        [--refine p2p|gicp] [--seed N]
// Not installed; a measuring tool for tests/cpp/registration and docs/BENCHMARK.md.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

#include "lidarloop/io/kitti_bin.hpp"
#include "registration/open3d_oracle.hpp"

namespace {

using lidarloop::test::Open3dOracleConfig;
using lidarloop::test::Open3dRefinement;
using lidarloop::test::Open3dRegistration;

constexpr const char* kUsage =
    "usage: open3d_register QUERY.bin MATCH.bin [--voxel M] [--refine-voxel M] [--max-range M]\n"
    "                       [--refine p2p|gicp] [--seed N]\n";

std::string JsonString(std::string_view text) {
    std::string out = "\"";
    for (const char c : text) {
        if (c == '"' || c == '\\') out += '\\';
        out += c;
    }
    return out + "\"";
}

double ParseNumber(const char* flag, const char* text) {
    char* end = nullptr;
    const double value = std::strtod(text, &end);
    if (end == text || *end != '\0') {
        throw std::invalid_argument(std::string(flag) + ": '" + text + "' is not a number");
    }
    return value;
}

// Voxel-dependent radii scale with --voxel as in Open3D's global registration tutorial.
Open3dOracleConfig ParseFlags(int argc, char** argv) {
    Open3dOracleConfig config;
    for (int i = 3; i < argc; i += 2) {
        const std::string_view flag = argv[i];
        if (i + 1 >= argc) throw std::invalid_argument(std::string(flag) + " needs a value");
        const char* value = argv[i + 1];
        if (flag == "--voxel") {
            config.voxel_m = ParseNumber("--voxel", value);
            config.normal_radius_m = 2.0 * config.voxel_m;
            config.feature_radius_m = 5.0 * config.voxel_m;
            config.ransac_distance_m = 1.5 * config.voxel_m;
        } else if (flag == "--refine-voxel") {
            config.refine_voxel_m = ParseNumber("--refine-voxel", value);
        } else if (flag == "--max-range") {
            config.max_range_m = ParseNumber("--max-range", value);
        } else if (flag == "--seed") {
            config.seed = static_cast<std::uint32_t>(ParseNumber("--seed", value));
        } else if (flag == "--refine" && std::string_view(value) == "p2p") {
            config.refinement = Open3dRefinement::kPointToPlane;
        } else if (flag == "--refine" && std::string_view(value) == "gicp") {
            config.refinement = Open3dRefinement::kGeneralizedIcp;
        } else {
            throw std::invalid_argument("unknown flag or value: " + std::string(flag) + " " +
                                        value);
        }
    }
    config.Validate();
    return config;
}

void PrintJson(const std::filesystem::path& query, const std::filesystem::path& match,
               const Open3dRegistration& r, double time_s) {
    std::printf("{\"query\": %s, \"match\": %s,\n \"T_match_query\": [",
                JsonString(query.string()).c_str(), JsonString(match.string()).c_str());
    const Eigen::Matrix4d& T = r.T_match_query.matrix();
    for (int row = 0; row < 4; ++row) {
        std::printf("%s[%.9g, %.9g, %.9g, %.9g]", row == 0 ? "" : ", ", T(row, 0), T(row, 1),
                    T(row, 2), T(row, 3));
    }
    std::printf(
        "],\n \"fitness\": %.6f, \"rmse_m\": %.6f, \"time_s\": %.3f,\n"
        " \"ransac_fitness\": %.6f, \"ransac_inliers\": %zu, \"query_points\": %zu, "
        "\"match_points\": %zu,\n \"features_s\": %.3f, \"ransac_s\": %.3f, \"refine_s\": %.3f}\n",
        r.fitness, r.rmse_m, time_s, r.ransac_fitness, r.ransac_inliers, r.query_points,
        r.match_points, r.times.features_s, r.times.ransac_s, r.times.refine_s);
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 3 || argc % 2 == 0) {
        std::fputs(kUsage, stderr);
        return 2;
    }
    try {
        const Open3dOracleConfig config = ParseFlags(argc, argv);
        const std::filesystem::path query_file = argv[1];
        const std::filesystem::path match_file = argv[2];
        const auto query = lidarloop::io::ReadKittiBin(query_file);
        const auto match = lidarloop::io::ReadKittiBin(match_file);
        const auto start = std::chrono::steady_clock::now();
        const Open3dRegistration result = lidarloop::test::RegisterWithOpen3d(query, match, config);
        const double time_s =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        PrintJson(query_file, match_file, result, time_s);
    } catch (const std::exception& error) {
        std::fprintf(stderr, "open3d_register: %s\n%s", error.what(), kUsage);
        return 1;
    }
    return 0;
}
