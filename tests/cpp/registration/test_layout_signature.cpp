#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "lidarloop/registration/coarse_alignment.hpp"
#include "lidarloop/registration/compact_prepared_scan.hpp"
#include "lidarloop/registration/layout_signature.hpp"

namespace lidarloop::registration {
namespace {

using Points = std::vector<Eigen::Vector3f>;

// Walls and poles within 28 m of the sensor, seeded.
Points Place(unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> coordinate(-26.0F, 26.0F), length(3.0F, 15.0F),
        heading(0.0F, std::numbers::pi_v<float>);
    Points points;
    for (int wall = 0; wall < 8; ++wall) {
        const Eigen::Vector2f start(coordinate(rng), coordinate(rng));
        const float angle = heading(rng), wall_length = length(rng);
        const Eigen::Vector2f along(std::cos(angle), std::sin(angle));
        for (float t = 0.0F; t < wall_length; t += 0.3F) {
            const Eigen::Vector2f p = start + t * along;
            if (p.cwiseAbs().maxCoeff() < 28.0F) points.emplace_back(p.x(), p.y(), 1.0F);
        }
    }
    for (int pole = 0; pole < 15; ++pole)
        points.emplace_back(coordinate(rng), coordinate(rng), 2.0F);
    return points;
}

Points Moved(const Points& points, float yaw_rad, const Eigen::Vector2f& shift_m) {
    const Eigen::Matrix2f rotation = Eigen::Rotation2Df(yaw_rad).toRotationMatrix();
    Points moved;
    for (const auto& p : points) {
        const Eigen::Vector2f xy = rotation * p.head<2>() + shift_m;
        moved.emplace_back(xy.x(), xy.y(), p.z());
    }
    return moved;
}

// The signature by its definition, independently of the FFT: each polar sample's Fourier
// coefficient summed directly over the image, log(1 + |F|), zero mean, unit norm.
std::vector<double> DirectSignature(const Points& points) {
    const CoarseConfig geometry;
    const int n = geometry.grid_cells;
    const std::vector<float> image = OccupancyImage(points, 0.0, geometry);
    std::vector<double> values;
    for (int r = 0; r < LayoutSignature::kRadii; ++r) {
        for (int a = 0; a < LayoutSignature::kAngles; ++a) {
            const double angle = std::numbers::pi * a / LayoutSignature::kAngles;
            const double kx = static_cast<double>(std::lround((r + 2) * std::cos(angle)));
            const double ky = static_cast<double>(std::lround((r + 2) * std::sin(angle)));
            std::complex<double> sum = 0.0;
            for (int y = 0; y < n; ++y) {
                for (int x = 0; x < n; ++x) {
                    const float value = image[static_cast<std::size_t>(y * n + x)];
                    if (value == 0.0F) continue;
                    sum += std::polar(1.0, -2.0 * std::numbers::pi * (kx * x + ky * y) / n);
                }
            }
            values.push_back(std::log1p(std::abs(sum)));
        }
    }
    double mean = 0.0, norm = 0.0;
    for (const double v : values) mean += v / static_cast<double>(values.size());
    for (double& v : values) v -= mean, norm += v * v;
    for (double& v : values) v /= std::sqrt(norm);
    return values;
}

// The largest correlation over angle shifts, in double, shift by shift.
double BruteForceSimilarity(const LayoutSignature& a, const LayoutSignature& b) {
    const int angles = LayoutSignature::kAngles;
    double best = -2.0;
    for (int shift = 0; shift < angles; ++shift) {
        double sum = 0.0;
        for (int r = 0; r < LayoutSignature::kRadii; ++r) {
            for (int k = 0; k < angles; ++k) {
                sum += double{a.values[static_cast<std::size_t>(r * angles + k)]} *
                       b.values[static_cast<std::size_t>(r * angles + (k + shift) % angles)];
            }
        }
        best = std::max(best, sum);
    }
    return best;
}

// The scalar float sums the shortlists were ranked by before the kernel was vectorised: per
// radius and shift over k in order, then over radii. Rounding reorders near-equal shortlists
// (docs/BENCHMARK.md, "Eight-bit layout signatures"), so the kernel must give these exactly.
double ScalarFloatSimilarity(const LayoutSignature& a, const LayoutSignature& b) {
    const int angles = LayoutSignature::kAngles;
    std::vector<float> shifted(static_cast<std::size_t>(angles), 0.0F);
    for (int r = 0; r < LayoutSignature::kRadii; ++r) {
        for (int shift = 0; shift < angles; ++shift) {
            float sum = 0.0F;
            for (int k = 0; k < angles; ++k) {
                sum += a.values[static_cast<std::size_t>(r * angles + k)] *
                       b.values[static_cast<std::size_t>(r * angles + (k + shift) % angles)];
            }
            shifted[static_cast<std::size_t>(shift)] += sum;
        }
    }
    return *std::max_element(shifted.begin(), shifted.end());
}

TEST(LayoutSignature, EqualsTheFourierSumsOfItsDefinition) {
    const Points place = Place(1);
    const LayoutSignature signature = ComputeLayoutSignature(place);
    const std::vector<double> expected = DirectSignature(place);
    ASSERT_EQ(signature.values.size(), expected.size());
    for (std::size_t i = 0; i < expected.size(); ++i)
        EXPECT_NEAR(signature.values[i], expected[i], 1e-5) << i;
}

TEST(LayoutSignature, SimilarityIsTheBestCorrelationOverTheAngleShifts) {
    const LayoutSignature a = ComputeLayoutSignature(Place(1));
    for (unsigned seed : {1U, 2U, 3U}) {
        const LayoutSignature b = ComputeLayoutSignature(Moved(Place(seed), 0.7F, {2.0F, 1.0F}));
        EXPECT_NEAR(LayoutSimilarity(a, b), BruteForceSimilarity(a, b), 1e-5) << seed;
        EXPECT_NEAR(LayoutSimilarity(a, b), LayoutSimilarity(b, a), 1e-5) << seed;
    }
    EXPECT_NEAR(LayoutSimilarity(a, a), 1.0, 1e-5);
}

TEST(LayoutSignature, SimilarityRoundsAsTheScalarSumsDo) {
    for (unsigned seed : {1U, 2U, 3U, 4U, 5U}) {
        const LayoutSignature a = ComputeLayoutSignature(Place(seed));
        const LayoutSignature b = ComputeLayoutSignature(
            Moved(Place(seed + 10U), 0.3F * static_cast<float>(seed), {1.0F, -2.0F}));
        EXPECT_EQ(LayoutSimilarity(a, b), ScalarFloatSimilarity(a, b)) << seed;
        EXPECT_EQ(LayoutSimilarity(b, a), ScalarFloatSimilarity(b, a)) << seed;
    }
}

// A translation changes the transform's phase only; a quarter turn is 18 angle steps.
TEST(LayoutSignature, AlikeWhereverTheSensorStoodAndWhicheverWayItLooked) {
    const Points place = Place(1);
    const LayoutSignature signature = ComputeLayoutSignature(place);
    EXPECT_GT(
        LayoutSimilarity(signature, ComputeLayoutSignature(Moved(place, 0.0F, {3.0F, -4.5F}))),
        0.999);  // whole cells
    Points turned;
    for (const auto& p : place) turned.emplace_back(-p.y(), p.x(), p.z());
    const LayoutSignature quarter = ComputeLayoutSignature(turned);
    EXPECT_GT(LayoutSimilarity(signature, quarter), 0.99);
    double unshifted = 0.0;
    for (std::size_t i = 0; i < signature.values.size(); ++i)
        unshifted += double{signature.values[i]} * quarter.values[i];
    EXPECT_LT(unshifted, 0.9);  // the turn is found by the shift
}

TEST(LayoutSignature, APlaceSeenAgainIsMoreAlikeThanOtherPlaces) {
    for (unsigned seed = 1; seed <= 5; ++seed) {
        const LayoutSignature again =
            ComputeLayoutSignature(Moved(Place(seed), 0.65F, {2.2F, -1.3F}));
        const double same = LayoutSimilarity(ComputeLayoutSignature(Place(seed)), again);
        for (unsigned other = 1; other <= 5; ++other) {
            if (other == seed) continue;
            EXPECT_GT(same, LayoutSimilarity(ComputeLayoutSignature(Place(other)), again))
                << seed << " " << other;
        }
    }
}

// match = Rz(yaw) query + shift: LayoutYaw finds the yaw of T_match_query, modulo half a turn,
// within a few degrees (the polar samples are 5 degrees apart, and coarser at low radii).
TEST(LayoutSignature, YawTurnsTheQuerysLayoutOntoTheMatchs) {
    const double deg = std::numbers::pi / 180.0;
    for (unsigned seed : {1U, 3U}) {
        const Points place = Place(seed);
        const LayoutSignature query = ComputeLayoutSignature(place);
        for (const double yaw_deg : {0.0, 12.0, 47.5, 90.0, 133.0, 200.0, 301.0, 358.0}) {
            const LayoutSignature match = ComputeLayoutSignature(
                Moved(place, static_cast<float>(yaw_deg * deg), {2.5F, -1.5F}));
            const double found = LayoutYaw(query, match);
            EXPECT_GE(found, 0.0);
            EXPECT_LT(found, std::numbers::pi);
            EXPECT_LT(std::abs(std::remainder(found - yaw_deg * deg, std::numbers::pi)), 3.0 * deg)
                << seed << " " << yaw_deg << ": " << found / deg;
            // The default window holds the turn, not a quarter turn from it.
            const YawWindow window = LayoutYawWindow(query, match, CoarseConfig{});
            EXPECT_TRUE(window.Contains(yaw_deg * deg)) << seed << " " << yaw_deg;
            EXPECT_FALSE(window.Contains((yaw_deg + 90.0) * deg)) << seed << " " << yaw_deg;
        }
        EXPECT_TRUE(std::isnan(LayoutYaw(query, {})));
        EXPECT_TRUE(std::isnan(LayoutYaw({}, query)));
        EXPECT_TRUE(LayoutYawWindow(query, {}, CoarseConfig{}).Whole());
    }
}

TEST(LayoutSignature, NoStructureNoSignature) {
    EXPECT_TRUE(ComputeLayoutSignature({}).empty());
    // One point: every magnitude is 1, no contrast.
    EXPECT_TRUE(ComputeLayoutSignature({Eigen::Vector3f(5, 5, 1)}).empty());
    // Points outside the image are not in it.
    EXPECT_TRUE(ComputeLayoutSignature({Eigen::Vector3f(500, 0, 1)}).empty());
    const LayoutSignature some = ComputeLayoutSignature(Place(1));
    EXPECT_TRUE(std::isnan(LayoutSimilarity(some, {})));
    EXPECT_TRUE(std::isnan(LayoutSimilarity({}, some)));
}

TEST(LayoutSignature, ACompactScanKeepsItsStructuresSignature) {
    PreparedScan scan;
    const Points place = Place(2);
    scan.structure = std::make_shared<const SurfacePoints>(
        place, std::vector<Eigen::Vector3f>(place.size(), Eigen::Vector3f::UnitX()));
    scan.ground = std::make_shared<const SurfacePoints>(Points{}, Points{});
    scan.structure_distinctive.assign(place.size(), 1);
    const CompactPreparedScan compact(scan);
    const PreparedScan stored = compact.Expand();
    EXPECT_EQ(compact.layout().values, ComputeLayoutSignature(stored.structure->points()).values);
    EXPECT_GT(LayoutSimilarity(compact.layout(), ComputeLayoutSignature(place)), 0.999);
    // Saved as it is stored and loaded again (a map): the same layout.
    EXPECT_EQ(CompactPreparedScan(stored).layout().values, compact.layout().values);
    EXPECT_GE(compact.MemoryBytes(), compact.layout().values.size() * sizeof(float));
    EXPECT_TRUE(CompactPreparedScan().layout().empty());
}

}  // namespace
}  // namespace lidarloop::registration
