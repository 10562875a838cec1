// Kernels of registration against brute force: the float k-d tree, the 2-D FFT, scan reduction.
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>
#include <unsupported/Eigen/FFT>

#include "lidarloop/registration/coarse_alignment.hpp"
#include "lidarloop/registration/detail/fft2d.hpp"
#include "lidarloop/registration/neighbor_grid.hpp"
#include "lidarloop/registration/point_tree.hpp"
#include "lidarloop/registration/prepared_scan.hpp"
#include "registration_test_utils.hpp"

namespace lidarloop::registration {
namespace {

std::vector<Eigen::Vector3f> RandomPoints(std::size_t n, std::uint64_t seed, float extent_m) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> u(-extent_m, extent_m);
    std::vector<Eigen::Vector3f> points(n);
    for (auto& p : points) p = Eigen::Vector3f{u(rng), u(rng), u(rng)};
    return points;
}

TEST(PointTree, NearestMatchesBruteForceWithinTheBound) {
    const auto points = RandomPoints(2000, 1, 20.0F);
    const PointTree tree(&points);
    for (const auto& query : RandomPoints(500, 2, 22.0F)) {
        std::int64_t best = -1;
        float best_m2 = 1.5F * 1.5F;
        for (std::size_t i = 0; i < points.size(); ++i) {
            const float d2 = (points[i] - query).squaredNorm();
            if (d2 < best_m2) best_m2 = d2, best = static_cast<std::int64_t>(i);
        }
        const auto found = tree.Nearest(query, 1.5F);
        if (best < 0) {
            EXPECT_EQ(found, -1);
        } else {
            ASSERT_GE(found, 0);
            // Equal distance (ties may pick either index).
            EXPECT_FLOAT_EQ((points[static_cast<std::size_t>(found)] - query).squaredNorm(),
                            best_m2);
        }
    }
}

// A hint (ICP's partner of the previous iteration) only prunes: good, bad, far, absent or out of
// range, the answer is the brute-force nearest within the bound.
TEST(PointTree, NearestWithAnyHintMatchesBruteForce) {
    const auto points = RandomPoints(2000, 5, 20.0F);
    const PointTree tree(&points);
    std::mt19937_64 rng(6);
    std::uniform_int_distribution<std::int64_t> any(0, 1999);
    for (const auto& query : RandomPoints(300, 7, 22.0F)) {
        std::int64_t best = -1, farther = -1;  // farther: in the bound, not the nearest
        float best_m2 = 1.5F * 1.5F;
        for (std::size_t i = 0; i < points.size(); ++i) {
            const float d2 = (points[i] - query).squaredNorm();
            if (d2 < 1.5F * 1.5F && best >= 0)
                farther = d2 < best_m2 ? best : static_cast<std::int64_t>(i);
            if (d2 < best_m2) best_m2 = d2, best = static_cast<std::int64_t>(i);
        }
        const std::vector<std::int64_t> hints = {-1,      any(rng), best,
                                                 farther, 2000,     std::int64_t{1} << 40};
        for (const std::int64_t hint : hints) {
            const auto found = tree.Nearest(query, 1.5F, hint);
            if (best < 0) {
                EXPECT_EQ(found, -1) << hint;
            } else {
                ASSERT_GE(found, 0) << hint;
                EXPECT_FLOAT_EQ((points[static_cast<std::size_t>(found)] - query).squaredNorm(),
                                best_m2)
                    << hint;
            }
        }
    }
}

TEST(PointTree, KnnMatchesBruteForce) {
    const auto points = RandomPoints(1000, 3, 10.0F);
    const PointTree tree(&points);
    std::vector<std::uint32_t> found;
    for (const auto& query : RandomPoints(100, 4, 10.0F)) {
        tree.Knn(query, 7, found);
        std::vector<float> all;
        for (const auto& p : points) all.push_back((p - query).squaredNorm());
        std::sort(all.begin(), all.end());
        ASSERT_EQ(found.size(), 7u);
        for (std::size_t i = 0; i < found.size(); ++i)
            EXPECT_FLOAT_EQ((points[found[i]] - query).squaredNorm(), all[i]);
    }
}

TEST(PointTree, EmptyTreeFindsNothing) {
    const std::vector<Eigen::Vector3f> none;
    const PointTree tree(&none);
    EXPECT_EQ(tree.Nearest(Eigen::Vector3f::Zero(), 10.0F), -1);
    std::vector<std::uint32_t> found;
    tree.Knn(Eigen::Vector3f::Zero(), 3, found);
    EXPECT_TRUE(found.empty());
}

// The squared distances of the k nearest of `points` to `query`, by brute force, nearest first.
std::vector<float> NearestSquaredDistances(const std::vector<Eigen::Vector3f>& points,
                                           const Eigen::Vector3f& query, std::size_t k) {
    std::vector<float> all;
    for (const auto& p : points) all.push_back((p - query).squaredNorm());
    const auto kept = all.begin() + static_cast<std::ptrdiff_t>(std::min(k, all.size()));
    std::partial_sort(all.begin(), kept, all.end());
    all.erase(kept, all.end());
    return all;
}

void ExpectGridKnnIsExact(const std::vector<Eigen::Vector3f>& points, float cell_m,
                          const std::vector<Eigen::Vector3f>& queries, int k) {
    const NeighborGrid grid(points, cell_m);
    NeighborGrid::Scratch scratch;  // shared by all queries, as PrepareScan shares it
    std::vector<std::uint32_t> found;
    for (const auto& query : queries) {
        grid.Knn(query, k, scratch, found);
        const auto expected = NearestSquaredDistances(points, query, static_cast<std::size_t>(k));
        ASSERT_EQ(found.size(), expected.size());
        for (std::size_t i = 0; i < found.size(); ++i) {
            const float squared_m2 = (points[found[i]] - query).squaredNorm();
            ASSERT_FLOAT_EQ(squared_m2, expected[i]) << i;
            // Equal distances (summed x, y, z in turn, as the grid and nanoflann sum them) by
            // index, as PointTree::Knn orders them.
            const auto summed_m2 = [&](std::uint32_t j) {
                const Eigen::Vector3f d = points[j] - query;
                return d.x() * d.x() + d.y() * d.y() + d.z() * d.z();
            };
            if (i > 0 && summed_m2(found[i]) == summed_m2(found[i - 1])) {
                ASSERT_LT(found[i - 1], found[i]) << i;
            }
        }
    }
}

// Uniform points, queries inside and well outside them, k from 1 to more than there are points:
// each query starts from the radius the last one left, too small or far too large.
TEST(NeighborGrid, KnnMatchesBruteForce) {
    const auto points = RandomPoints(1500, 11, 10.0F);
    const auto queries = RandomPoints(150, 12, 30.0F);
    for (const int k : {1, 5, 10, 30, 1499, 1500, 2000})
        for (const float cell_m : {0.05F, 0.5F, 3.0F, 100.0F})
            ExpectGridKnnIsExact(points, cell_m, queries, k);
}

// A scan's kind of cloud: dense walls and ground near the sensor, a few far points. The grid
// must widen its columns for the far ones and still find the exact neighbours everywhere.
TEST(NeighborGrid, KnnIsExactOnAScanWithFarOutliers) {
    std::vector<Eigen::Vector3f> points;
    for (const auto& p : test::SyntheticPlace(3)) points.push_back(p);
    points.emplace_back(1e6F, -1e6F, 5.0F);
    points.emplace_back(-3e5F, 2e5F, -40.0F);
    std::vector<Eigen::Vector3f> queries(points.begin(), points.begin() + 300);
    queries.push_back(points.back());
    ExpectGridKnnIsExact(points, 0.5F, queries, 10);
    ExpectGridKnnIsExact(points, 0.5F, queries, 30);
}

TEST(NeighborGrid, EqualPointsAndOneColumnAreHandled) {
    const std::vector<Eigen::Vector3f> same(50, Eigen::Vector3f(1.0F, 2.0F, 3.0F));
    ExpectGridKnnIsExact(same, 0.5F, {Eigen::Vector3f(1.0F, 2.0F, 3.0F)}, 10);
    ExpectGridKnnIsExact(same, 0.5F, {Eigen::Vector3f(1.0F, 2.0F, 3.0F)}, 50);  // many candidates
    std::vector<Eigen::Vector3f> pole;
    for (int i = 0; i < 200; ++i) pole.emplace_back(0.0F, 0.0F, 0.1F * static_cast<float>(i));
    ExpectGridKnnIsExact(pole, 0.5F, RandomPoints(50, 13, 5.0F), 7);
}

TEST(NeighborGrid, NothingToFindGivesNothing) {
    const std::vector<Eigen::Vector3f> none;
    const NeighborGrid empty(none, 0.5F);
    NeighborGrid::Scratch scratch;
    std::vector<std::uint32_t> found = {7};
    empty.Knn(Eigen::Vector3f::Zero(), 3, scratch, found);
    EXPECT_TRUE(found.empty());
    const auto points = RandomPoints(100, 14, 5.0F);
    const NeighborGrid grid(points, 0.5F);
    grid.Knn(Eigen::Vector3f::Zero(), 0, scratch, found);
    EXPECT_TRUE(found.empty());
    const float nan = std::numeric_limits<float>::quiet_NaN();
    grid.Knn(Eigen::Vector3f(nan, 0.0F, 0.0F), 3, scratch, found);
    EXPECT_TRUE(found.empty());
    // An unusable column edge falls back to a usable one.
    ExpectGridKnnIsExact(points, nan, RandomPoints(20, 15, 5.0F), 4);
    ExpectGridKnnIsExact(points, -1.0F, RandomPoints(20, 15, 5.0F), 4);
    // Absurdly fine columns are widened until there are a few per point.
    ExpectGridKnnIsExact(points, 1e-30F, RandomPoints(20, 15, 5.0F), 4);
}

// The brute-force nearest of `points` to `query` closer than `bound_m`: its squared distance,
// or -1 when there is none.
float BruteNearestWithin(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& query,
                         float bound_m) {
    float best_m2 = -1.0F;
    for (const auto& p : points) {
        const float d2 = (p - query).squaredNorm();
        if (d2 < bound_m * bound_m && (best_m2 < 0.0F || d2 < best_m2)) best_m2 = d2;
    }
    return best_m2;
}

void ExpectGridNearestIsExact(const std::vector<Eigen::Vector3f>& points, float cell_m,
                              const std::vector<Eigen::Vector3f>& queries, float bound_m) {
    const NeighborGrid grid(points, cell_m);
    const PointTree tree(&points);
    std::mt19937_64 rng(21);
    std::uniform_int_distribution<std::int64_t> any(0, static_cast<std::int64_t>(points.size()));
    for (const auto& query : queries) {
        const float expected_m2 = BruteNearestWithin(points, query, bound_m);
        const auto tree_nearest = tree.Nearest(query, bound_m);
        // Hints as ICP gives them: none, the answer, any point, out of range.
        for (const std::int64_t hint :
             {std::int64_t{-1}, tree_nearest, any(rng), static_cast<std::int64_t>(points.size()),
              std::int64_t{1} << 40}) {
            const auto found = grid.NearestWithin(query, bound_m, hint);
            if (expected_m2 < 0.0F) {
                ASSERT_EQ(found, -1) << hint;
                continue;
            }
            ASSERT_GE(found, 0) << hint;
            ASSERT_LT(found, static_cast<std::int64_t>(points.size()));
            ASSERT_FLOAT_EQ((points[static_cast<std::size_t>(found)] - query).squaredNorm(),
                            expected_m2)
                << hint << " cell " << cell_m << " bound " << bound_m;
        }
    }
}

// What ICP and the overlap test ask: the nearest point within a bound, with or without the last
// partner as a hint, queries inside and far outside the cloud, columns of any width.
TEST(NeighborGrid, NearestWithinMatchesBruteForceWithAnyHint) {
    const auto points = RandomPoints(1500, 16, 10.0F);
    const auto queries = RandomPoints(150, 17, 14.0F);
    for (const float bound_m : {0.3F, 1.5F, 3.0F, 100.0F})
        for (const float cell_m : {0.05F, 0.5F, 1.0F, 3.0F, 100.0F})
            ExpectGridNearestIsExact(points, cell_m, queries, bound_m);
}

// A scan's kind of cloud, with far outliers that widen the columns, queried near its own points
// (a registered pair's partners are centimetres away) and between them.
TEST(NeighborGrid, NearestWithinIsExactOnAScan) {
    std::vector<Eigen::Vector3f> points;
    for (const auto& p : test::SyntheticPlace(4)) points.push_back(p);
    std::vector<Eigen::Vector3f> queries;
    std::mt19937_64 rng(18);
    std::normal_distribution<float> jitter(0.0F, 0.2F);
    for (std::size_t i = 0; i < points.size(); i += 37)
        queries.push_back(points[i] + Eigen::Vector3f{jitter(rng), jitter(rng), jitter(rng)});
    for (const float bound_m : {0.6F, 1.5F, 3.0F}) {
        ExpectGridNearestIsExact(points, 1.0F, queries, bound_m);
        ExpectGridNearestIsExact(points, 0.3F, queries, bound_m);
    }
    points.emplace_back(1e6F, -1e6F, 5.0F);
    queries.push_back(points.back() + Eigen::Vector3f(0.5F, 0.0F, 0.0F));
    ExpectGridNearestIsExact(points, 1.0F, queries, 3.0F);
}

TEST(NeighborGrid, NearestWithinKeepsAnEquallyNearHintAndRejectsBadInput) {
    const std::vector<Eigen::Vector3f> same(50, Eigen::Vector3f(1.0F, 2.0F, 3.0F));
    const NeighborGrid grid(same, 0.5F);
    const Eigen::Vector3f near(1.1F, 2.0F, 3.0F);
    EXPECT_EQ(grid.NearestWithin(near, 1.0F, 37), 37);  // as PointTree::Nearest keeps it
    EXPECT_GE(grid.NearestWithin(near, 1.0F), 0);
    EXPECT_EQ(grid.NearestWithin(near, 0.05F, 37), -1);  // the hint is beyond the bound
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    EXPECT_EQ(grid.NearestWithin(Eigen::Vector3f(nan, 2.0F, 3.0F), 1.0F), -1);
    EXPECT_EQ(grid.NearestWithin(Eigen::Vector3f(inf, 2.0F, 3.0F), 1.0F), -1);
    EXPECT_EQ(grid.NearestWithin(near, 0.0F), -1);
    EXPECT_EQ(grid.NearestWithin(near, -1.0F), -1);
    EXPECT_EQ(grid.NearestWithin(near, nan), -1);
    EXPECT_EQ(grid.NearestWithin(near, inf), std::int64_t{0});
    const std::vector<Eigen::Vector3f> none;
    EXPECT_EQ(NeighborGrid(none, 0.5F).NearestWithin(near, 10.0F, 0), -1);
}

// n = 8 and 32: an even and an odd number of stages (the result ends in the scratch buffers).
TEST(Fft2d, MatchesTheDefinitionAndInverts) {
    for (const int n : {8, 32}) {
        std::mt19937_64 rng(5);
        std::uniform_real_distribution<float> u(-1.0F, 1.0F);
        std::vector<std::complex<float>> grid(n * n);
        for (auto& v : grid) v = {u(rng), u(rng)};
        auto spectrum = grid;
        detail::Fft2dForward(spectrum, n);
        for (int ky = 0; ky < n; ++ky) {
            for (int kx = 0; kx < n; ++kx) {
                std::complex<double> sum = 0.0;
                for (int y = 0; y < n; ++y)
                    for (int x = 0; x < n; ++x)
                        sum += std::complex<double>(grid[y * n + x]) *
                               std::polar(1.0, -2.0 * M_PI * (kx * x + ky * y) / n);
                EXPECT_NEAR(spectrum[ky * n + kx].real(), sum.real(), 1e-4);
                EXPECT_NEAR(spectrum[ky * n + kx].imag(), sum.imag(), 1e-4);
            }
        }
        auto back = spectrum;
        detail::Fft2dInverse(back, n);
        for (int i = 0; i < n * n; ++i) EXPECT_NEAR(std::abs(back[i] - grid[i]), 0.0, 1e-5);
        // The partial inverse computes the listed rows only, column by column; they equal the full
        // one's.
        detail::SplitGrid partial, narrow;
        for (const auto& v : spectrum)
            partial.re.push_back(v.real()), partial.im.push_back(v.imag());
        const std::vector<int> rows = {1, 5};
        detail::Fft2dInverseRows(partial, n, rows, narrow);
        ASSERT_EQ(narrow.re.size(), rows.size() * n);
        for (std::size_t j = 0; j < rows.size(); ++j) {
            for (int x = 0; x < n; ++x) {
                const std::size_t at = x * rows.size() + j;
                EXPECT_NEAR(narrow.re[at], grid[rows[j] * n + x].real(), 1e-5);
                EXPECT_NEAR(narrow.im[at], grid[rows[j] * n + x].imag(), 1e-5);
            }
        }
    }
}

// The batched kernel against Eigen's FFT, one 1-D transform at a time, at the sizes the coarse
// search allows.
TEST(Fft2d, EqualsEigensFftOnRowsThenColumns) {
    for (const int n : {16, 32, 64, 128, 256}) {
        std::mt19937_64 rng(static_cast<unsigned>(n));
        std::uniform_real_distribution<float> u(-1.0F, 1.0F);
        std::vector<std::complex<float>> grid(static_cast<std::size_t>(n * n));
        for (auto& v : grid) v = {u(rng), u(rng)};
        for (const bool inverse : {false, true}) {
            std::vector<std::complex<float>> expected = grid, in(n), out(n);
            Eigen::FFT<float> fft;
            const auto run = [&] { inverse ? fft.inv(out, in) : fft.fwd(out, in); };
            for (int row = 0; row < n; ++row) {
                std::copy_n(expected.begin() + row * n, n, in.begin());
                run();
                std::copy(out.begin(), out.end(), expected.begin() + row * n);
            }
            for (int col = 0; col < n; ++col) {
                for (int row = 0; row < n; ++row) in[row] = expected[row * n + col];
                run();
                for (int row = 0; row < n; ++row) expected[row * n + col] = out[row];
            }
            auto actual = grid;
            inverse ? detail::Fft2dInverse(actual, n) : detail::Fft2dForward(actual, n);
            const float tolerance = (inverse ? 1e-5F : 1e-3F) * static_cast<float>(n) / 16.0F;
            for (std::size_t i = 0; i < grid.size(); ++i)
                ASSERT_NEAR(std::abs(actual[i] - expected[i]), 0.0F, tolerance)
                    << "n " << n << " inverse " << inverse << " at " << i;
        }
    }
}

TEST(Fft2d, ARealPairSplitsIntoTheSpectraOfEachImage) {
    for (const int n : {16, 32}) {
        std::mt19937_64 rng(6);
        std::uniform_real_distribution<float> u(0.0F, 1.0F);
        std::vector<float> a(n * n), b(n * n);
        for (auto& v : a) v = u(rng);
        for (auto& v : b) v = u(rng) > 0.7F ? 1.0F : 0.0F;
        std::vector<std::complex<float>> spectrum_a, spectrum_b;
        detail::Fft2dForwardRealPair(a, b, n, spectrum_a, spectrum_b);
        for (const auto& [image, spectrum] :
             {std::pair{&a, &spectrum_a}, std::pair{&b, &spectrum_b}}) {
            std::vector<std::complex<float>> expected(image->begin(), image->end());
            detail::Fft2dForward(expected, n);
            ASSERT_EQ(spectrum->size(), expected.size());
            for (std::size_t i = 0; i < expected.size(); ++i)
                EXPECT_NEAR(std::abs((*spectrum)[i] - expected[i]), 0.0, 1e-3) << n << " " << i;
        }
    }
}

// The images are computed from columns in one vectorised pass per yaw; they must be those of
// rotating each point with Eigen and flooring its cell, to the last cell: points beyond the
// image's edge (it spans +-48 m), and points on the cell edges, where a rounding decides.
TEST(OccupancyImage, EqualsRotatingEachPointWithEigen) {
    auto points = RandomPoints(4000, 9, 70.0F);
    for (int i = -40; i <= 40; ++i) {
        const float edge_m = 1.5F * static_cast<float>(i);
        points.emplace_back(edge_m, 0.5F * edge_m, 0.0F);
        points.emplace_back(-0.25F * edge_m, edge_m, 0.0F);
    }
    const CoarseConfig config;
    const int n = config.grid_cells;
    for (int step = 0; step < 72; ++step) {
        const double yaw_rad = step * 5.0 * std::numbers::pi / 180.0;
        std::vector<float> expected(static_cast<std::size_t>(n * n), 0.0F);
        const Eigen::Rotation2Df rotation(static_cast<float>(yaw_rad));
        const auto inverse_cell = static_cast<float>(1.0 / config.cell_m);
        for (const auto& point : points) {
            const Eigen::Vector2f xy = rotation * point.head<2>();
            const int x = static_cast<int>(std::floor(xy.x() * inverse_cell)) + n / 2;
            const int y = static_cast<int>(std::floor(xy.y() * inverse_cell)) + n / 2;
            if (x >= 0 && y >= 0 && x < n && y < n)
                expected[static_cast<std::size_t>(y * n + x)] = 1;
        }
        ASSERT_EQ(OccupancyImage(points, yaw_rad, config), expected) << "yaw step " << step;
    }
}

TEST(CoarseQuery, HoldsTheConjugateSpectrumOfTheRotatedImageAtEveryYaw) {
    ScanReductionConfig reduction;
    const PreparedScan scan = PrepareScan(test::SyntheticPlace(), reduction);
    CoarseConfig config;
    config.yaw_step_deg = 360.0 / 9.0;  // an odd count: the last yaw has no partner
    const CoarseQuery query(*scan.structure, config);
    ASSERT_EQ(query.yaw_count(), 9);
    for (int i = 0; i < query.yaw_count(); ++i) {
        const auto image = OccupancyImage(scan.structure->points(), query.YawOf(i), config);
        std::vector<std::complex<float>> expected(image.begin(), image.end());
        detail::Fft2dForward(expected, config.grid_cells);
        for (std::size_t k = 0; k < expected.size(); ++k)
            ASSERT_NEAR(std::abs(query.spectrum(i)[k] - std::conj(expected[k])), 0.0, 1e-2)
                << "yaw " << i << " frequency " << k;
    }
}

// A query's pairs are registered on several threads, each asking for the spectra it needs:
// threads asking for the same yaws at once get what one thread computes alone.
TEST(CoarseQuery, SpectraAskedByThreadsAtOnceAreThoseOfOneThread) {
    const PreparedScan scan = PrepareScan(test::SyntheticPlace(), ScanReductionConfig{});
    const CoarseConfig config;
    const CoarseQuery alone(*scan.structure, config);
    const CoarseQuery shared(*scan.structure, config);
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t) {
        threads.emplace_back([&shared, t] {
            for (int k = 0; k < shared.yaw_count(); ++k)
                (void)shared.spectrum((k * 7 + t * 5) % shared.yaw_count());
        });
    }
    for (auto& thread : threads) thread.join();
    for (int i = 0; i < alone.yaw_count(); ++i) {
        ASSERT_TRUE(shared.Computed(i)) << i;
        ASSERT_EQ(shared.spectrum(i), alone.spectrum(i)) << i;
    }
}

// Correlations of 0/1 with 0/0.5/1 images are multiples of 0.5: the peaks' scores are exactly
// that, without the FFT's rounding error, so equal peaks tie whatever computed the transform.
TEST(CoarseAlign, ScoresAreExactMultiplesOfAHalf) {
    ScanReductionConfig reduction;
    const PreparedScan scan = PrepareScan(test::SyntheticPlace(), reduction);
    const CoarseQuery query(*scan.structure, CoarseConfig{});
    const auto hypotheses = CoarseAlign(query, *scan.structure);
    ASSERT_FALSE(hypotheses.empty());
    for (const PlanarHypothesis& h : hypotheses) {
        EXPECT_GT(h.score, 0.0);
        EXPECT_EQ(h.score * 2.0, std::round(h.score * 2.0)) << h.score;
    }
    EXPECT_NEAR(hypotheses.front().translation_m.norm(), 0.0, 0.2);  // the scan onto itself
    EXPECT_NEAR(hypotheses.front().yaw_rad, 0.0, 1e-9);
}

// The peak search's float pre-test against the plain search it shortcuts: every cell's
// correlation rounded to a multiple of 0.5, the first highest taken, then the highest more than
// 3 cells (wrapped) from each taken. Planes of multiples of 0.5 with the FFT's small errors and
// values at the rounding boundaries, one float step either side.
TEST(CoarseAlign, PeakCellsAreThoseOfTheSearchWithoutAShortcut) {
    constexpr int n = 16;
    std::vector<std::uint32_t> search_cells;
    for (int y = 0; y < n; ++y) {
        for (int x = 0; x < n; ++x) {
            const int dx = x < n / 2 ? x : x - n, dy = y < n / 2 ? y : y - n;
            if (dx * dx + dy * dy <= 36)
                search_cells.push_back(static_cast<std::uint32_t>(y * n + x));
        }
    }
    const auto rounded = [](float value) { return std::floor(2.0F * value + 0.5F) / 2.0; };
    const auto apart = [](std::uint32_t a, std::uint32_t b) {
        const auto wrapped = [](int d) { return std::min((d + n) % n, (n - d) % n); };
        const int dx = wrapped(static_cast<int>(a % n) - static_cast<int>(b % n));
        const int dy = wrapped(static_cast<int>(a / n) - static_cast<int>(b / n));
        return std::max(dx, dy) > 3;
    };
    const auto plain = [&](const std::vector<float>& plane, int count) {
        std::vector<std::uint32_t> taken;
        for (int k = 0; k < count; ++k) {
            double best = 0.0;
            std::int64_t at = -1;
            for (const std::uint32_t cell : search_cells) {
                const bool free = std::all_of(taken.begin(), taken.end(),
                                              [&](std::uint32_t t) { return apart(cell, t); });
                if (free && rounded(plane[cell]) > best) best = rounded(plane[cell]), at = cell;
            }
            if (at < 0) break;
            taken.push_back(static_cast<std::uint32_t>(at));
        }
        return taken;
    };
    std::mt19937 rng(17);
    std::uniform_int_distribution<int> halves(-1, 12);
    std::uniform_int_distribution<int> kind(0, 5);
    std::uniform_real_distribution<float> fft_error(-1e-3F, 1e-3F);
    std::size_t boundary_values = 0;
    for (int trial = 0; trial < 2000; ++trial) {
        std::vector<float> plane(static_cast<std::size_t>(n * n));
        for (float& value : plane) {
            const float half = 0.5F * static_cast<float>(halves(rng));
            const float edge = half + 0.25F;  // where rounding steps up to half + 0.5
            switch (kind(rng)) {
                case 0:
                    value = std::nextafter(edge, -1e9F), ++boundary_values;
                    break;
                case 1:
                    value = edge, ++boundary_values;
                    break;
                case 2:
                    value = std::nextafter(edge, 1e9F), ++boundary_values;
                    break;
                default:
                    value = half + fft_error(rng);
            }
        }
        for (const int count : {1, 2, 3})
            ASSERT_EQ(detail::PeakCells(plane, search_cells, search_cells, n, count),
                      plain(plane, count))
                << "trial " << trial << " count " << count;
    }
    EXPECT_GT(boundary_values, 10000u);
}

TEST(YawWindow, WrapsAroundAndANanWindowIsWhole) {
    const double deg = std::numbers::pi / 180.0;
    const YawWindow window{179.0 * deg, 5.0 * deg};
    EXPECT_TRUE(window.Contains(-177.0 * deg));
    EXPECT_TRUE(window.Contains(175.0 * deg));
    EXPECT_FALSE(window.Contains(-175.0 * deg));
    EXPECT_FALSE(window.Contains(0.0));
    EXPECT_TRUE(YawWindow{}.Whole());
    EXPECT_TRUE((YawWindow{std::numeric_limits<double>::quiet_NaN(), 5.0 * deg}.Whole()));
    EXPECT_TRUE((YawWindow{0.0, std::numeric_limits<double>::quiet_NaN()}.Contains(2.0)));
    EXPECT_NEAR(SearchedYaws(window, CoarseConfig{}).half_width_rad, 15.0 * deg, 1e-12);
}

TEST(YawWindow, HalfATurnTooHoldsTheOppositeWindow) {
    const double deg = std::numbers::pi / 180.0;
    const YawWindow both{20.0 * deg, 10.0 * deg, true};
    for (const double yaw_deg : {10.0, 29.0, 190.0, 209.0, -151.0})
        EXPECT_TRUE(both.Contains(yaw_deg * deg)) << yaw_deg;
    for (const double yaw_deg : {31.0, 100.0, 169.0, 215.0, -90.0})
        EXPECT_FALSE(both.Contains(yaw_deg * deg)) << yaw_deg;
    EXPECT_FALSE((YawWindow{20.0 * deg, 10.0 * deg}.Contains(200.0 * deg)));
    EXPECT_TRUE(SearchedYaws(both, CoarseConfig{}).half_turn_too);
}

// The query turned by 60 degrees: the full search's best peak lies at 60 degrees. A window
// there finds the same peak, bit for bit; a window elsewhere never looks at 60 degrees.
TEST(CoarseAlign, AYawWindowSearchesWithinItAndFindsWhatTheFullSearchFindsThere) {
    const double deg = std::numbers::pi / 180.0;
    const core::PointCloud place = test::SyntheticPlace();
    const PreparedScan match = PrepareScan(place, ScanReductionConfig{});
    const PreparedScan query = PrepareScan(
        test::Transformed(place, test::PlanarTransform(0.0, 0.0, -60.0)), ScanReductionConfig{});
    const CoarseConfig config;
    const CoarseQuery full(*query.structure, config);
    const auto everywhere = CoarseAlign(full, *match.structure);
    ASSERT_FALSE(everywhere.empty());
    ASSERT_NEAR(everywhere.front().yaw_rad, 60.0 * deg, 1e-9);
    // Searched: within 12 + 10 degrees, the yaws 40-80 and 130-170 degrees, 9 each.
    const YawWindow right{60.0 * deg, 12.0 * deg}, wrong{150.0 * deg, 12.0 * deg};
    const CoarseQuery windowed(*query.structure, config, {wrong, right});
    for (const YawWindow& window : {right, wrong}) {
        const auto found = CoarseAlign(windowed, *match.structure, window);
        ASSERT_FALSE(found.empty());
        for (const PlanarHypothesis& h : found)
            EXPECT_TRUE(SearchedYaws(window, config).Contains(h.yaw_rad)) << h.yaw_rad / deg;
        // The same peaks from the query's images for every yaw.
        const auto from_full = CoarseAlign(full, *match.structure, window);
        ASSERT_EQ(found.size(), from_full.size());
        for (std::size_t i = 0; i < found.size(); ++i) {
            EXPECT_EQ(found[i].yaw_rad, from_full[i].yaw_rad);
            EXPECT_EQ(found[i].translation_m, from_full[i].translation_m);
            EXPECT_EQ(found[i].score, from_full[i].score);
        }
    }
    // A query's spectra are computed as its pairs need them: searching the right window first
    // computes its yaws and their partners in the paired transforms (8-9 ... 16-17) only.
    const CoarseQuery lazy(*query.structure, config, {wrong, right});
    for (int i = 0; i < lazy.yaw_count(); ++i) ASSERT_FALSE(lazy.Computed(i)) << i;
    const auto there = CoarseAlign(lazy, *match.structure, right);
    EXPECT_EQ(there.front().yaw_rad, everywhere.front().yaw_rad);
    EXPECT_EQ(there.front().translation_m, everywhere.front().translation_m);
    EXPECT_EQ(there.front().score, everywhere.front().score);
    std::vector<int> computed;
    for (int i = 0; i < lazy.yaw_count(); ++i) {
        if (lazy.Computed(i)) computed.push_back(i);
    }
    EXPECT_EQ(computed, (std::vector<int>{8, 9, 10, 11, 12, 13, 14, 15, 16, 17}));
    // It has the windows' yaws (40-80 and 130-170 degrees), nothing else.
    int held = 0;
    for (int i = 0; i < windowed.yaw_count(); ++i) held += windowed.Has(i) ? 1 : 0;
    EXPECT_EQ(held, 18);
    EXPECT_TRUE(windowed.Has(8) && windowed.Has(16) && windowed.Has(26) && windowed.Has(34));
    EXPECT_FALSE(windowed.Has(0) || windowed.Has(17) || windowed.Has(25));
    EXPECT_THROW(windowed.spectrum(0), std::invalid_argument);
    EXPECT_THROW(CoarseAlign(windowed, *match.structure, YawWindow{}), std::invalid_argument);
    EXPECT_THROW(CoarseAlign(windowed, *match.structure, YawWindow{-90.0 * deg, 10.0 * deg}),
                 std::invalid_argument);
    // A whole window is the full search.
    const CoarseQuery whole(*query.structure, config, {right, YawWindow{}});
    for (int i = 0; i < whole.yaw_count(); ++i) ASSERT_TRUE(whole.Has(i));
}

// The layouts give the yaw modulo half a turn. The query turned by 190 or 10 degrees, the
// window at 10 degrees and its half turn: the search correlates the yaw nearest each centre and
// searches the better one's window only, where the full search's best peak lies, bit for bit;
// of the other half it keeps the centre's peaks alone (possible rivals). Searching both halves
// (better_half_turn_only off) finds that peak too, among the other half's.
TEST(CoarseAlign, AHalfTurnWindowSearchesTheHalfWhoseCentreCorrelatesBetter) {
    const double deg = std::numbers::pi / 180.0;
    const core::PointCloud place = test::SyntheticPlace();
    const PreparedScan match = PrepareScan(place, ScanReductionConfig{});
    const YawWindow window{10.0 * deg, 15.0 * deg, true};
    CoarseConfig both_halves;
    both_halves.better_half_turn_only = false;
    for (const double truth_deg : {190.0, 10.0}) {
        const PreparedScan query =
            PrepareScan(test::Transformed(place, test::PlanarTransform(0.0, 0.0, -truth_deg)),
                        ScanReductionConfig{});
        const CoarseConfig config;
        const auto everywhere =
            CoarseAlign(CoarseQuery(*query.structure, config), *match.structure);
        ASSERT_FALSE(everywhere.empty());
        ASSERT_NEAR(everywhere.front().yaw_rad, truth_deg * deg, 1e-9);
        const auto better =
            CoarseAlign(CoarseQuery(*query.structure, config, {window}), *match.structure, window);
        ASSERT_FALSE(better.empty());
        const YawWindow right = SearchedYaws(YawWindow{truth_deg * deg, 15.0 * deg}, config);
        const double other_centre_rad = (truth_deg + 180.0) * deg;
        for (const PlanarHypothesis& h : better) {
            EXPECT_TRUE(right.Contains(h.yaw_rad) ||
                        std::abs(std::remainder(h.yaw_rad - other_centre_rad,
                                                2.0 * std::numbers::pi)) < 1e-9)
                << truth_deg << " " << h.yaw_rad / deg;
        }
        EXPECT_EQ(better.front().yaw_rad, everywhere.front().yaw_rad);
        EXPECT_EQ(better.front().translation_m, everywhere.front().translation_m);
        EXPECT_EQ(better.front().score, everywhere.front().score);

        const auto both = CoarseAlign(CoarseQuery(*query.structure, both_halves, {window}),
                                      *match.structure, window);
        ASSERT_FALSE(both.empty());
        EXPECT_EQ(both.front().yaw_rad, everywhere.front().yaw_rad) << truth_deg;
        EXPECT_TRUE(std::any_of(both.begin(), both.end(),
                                [&](const PlanarHypothesis& h) {
                                    return !right.Contains(h.yaw_rad) &&
                                           std::abs(std::remainder(h.yaw_rad - other_centre_rad,
                                                                   2.0 * std::numbers::pi)) > 1e-9;
                                }))
            << "the other half has peaks off its centre too: " << truth_deg;
    }
}

// A place that is the same after half a turn (each structure point's mirror through the sensor
// is one too): the two centres correlate alike, so both halves are searched, and tied peaks come
// in the order of their yaws, as when both halves are searched from the start, although the
// centres were correlated first (the window at 350 degrees: its half turn, 170, is the lower).
TEST(CoarseAlign, TiedHalfTurnsAreBothSearchedAndTheirPeaksKeepTheYawOrder) {
    const double deg = std::numbers::pi / 180.0;
    const PreparedScan place = PrepareScan(test::SyntheticPlace(), ScanReductionConfig{});
    std::vector<Eigen::Vector3f> points = place.structure->points();
    for (std::size_t i = 0, count = points.size(); i < count; ++i)
        points.emplace_back(-points[i].x(), -points[i].y(), points[i].z());
    const Eigen::Isometry3f turned = test::PlanarTransform(0.0, 0.0, -350.0).cast<float>();
    std::vector<Eigen::Vector3f> query_points;
    for (const auto& point : points) query_points.push_back(turned * point);
    const std::vector<Eigen::Vector3f> normals(points.size(), Eigen::Vector3f::UnitX());
    const SurfacePoints match(points, normals), query(query_points, normals);
    const YawWindow window{350.0 * deg, 15.0 * deg, true};
    CoarseConfig both_halves;
    both_halves.better_half_turn_only = false;
    const CoarseQuery searched(query, CoarseConfig{}, {window});
    const auto better = CoarseAlign(searched, match, window);
    const auto both = CoarseAlign(CoarseQuery(query, both_halves, {window}), match, window);
    // Yaws off either centre were transformed: 160 and 340 degrees.
    EXPECT_TRUE(searched.Computed(32) && searched.Computed(68));
    ASSERT_GE(better.size(), 2U);
    EXPECT_NEAR(better[0].yaw_rad, 170.0 * deg, 1e-9);
    EXPECT_NEAR(better[1].yaw_rad, 350.0 * deg, 1e-9);
    EXPECT_EQ(better[0].score, better[1].score);
    ASSERT_EQ(better.size(), both.size());
    for (std::size_t i = 0; i < better.size(); ++i) {
        EXPECT_EQ(better[i].yaw_rad, both[i].yaw_rad) << i;
        EXPECT_EQ(better[i].translation_m, both[i].translation_m) << i;
        EXPECT_EQ(better[i].score, both[i].score) << i;
    }
}

// 45 yaws of 8 degrees: the last one has no partner in the paired transforms, and a window
// around it wraps past 0. Searched: within 1 + 16 degrees of 352, the yaws 336-360 and 0-8.
TEST(CoarseAlign, AWindowWrapsAroundAnOddYawCount) {
    const double deg = std::numbers::pi / 180.0;
    const core::PointCloud place = test::SyntheticPlace();
    const PreparedScan match = PrepareScan(place, ScanReductionConfig{});
    const PreparedScan query = PrepareScan(
        test::Transformed(place, test::PlanarTransform(0.0, 0.0, 8.0)), ScanReductionConfig{});
    CoarseConfig config;
    config.yaw_step_deg = 8.0;
    const YawWindow window{352.0 * deg, 1.0 * deg};
    const CoarseQuery windowed(*query.structure, config, {window});
    ASSERT_EQ(windowed.yaw_count(), 45);
    std::vector<int> computed;
    for (int i = 0; i < windowed.yaw_count(); ++i) {
        if (windowed.Has(i)) computed.push_back(i);
    }
    EXPECT_EQ(computed, (std::vector<int>{0, 1, 42, 43, 44}));
    const auto found = CoarseAlign(windowed, *match.structure, window);
    const auto from_full =
        CoarseAlign(CoarseQuery(*query.structure, config), *match.structure, window);
    ASSERT_FALSE(found.empty());
    ASSERT_EQ(found.size(), from_full.size());
    for (std::size_t i = 0; i < found.size(); ++i) {
        EXPECT_TRUE(SearchedYaws(window, config).Contains(found[i].yaw_rad));
        EXPECT_EQ(found[i].yaw_rad, from_full[i].yaw_rad);
        EXPECT_EQ(found[i].translation_m, from_full[i].translation_m);
        EXPECT_EQ(found[i].score, from_full[i].score);
    }
}

// A pole at the sensor looks the same at every yaw: 72 peaks of equal score. The hypotheses are
// the first distinct ones in yaw order (0, 15 and 30 degrees: 5-degree steps, distinct beyond
// 2.5 steps), whatever the sort would do with ties.
TEST(CoarseAlign, TiedPeaksComeInYawOrder) {
    const std::vector<Eigen::Vector3f> pole(5, Eigen::Vector3f(0.0F, 0.0F, 1.0F));
    const SurfacePoints structure(pole, std::vector<Eigen::Vector3f>(5, Eigen::Vector3f::UnitX()));
    const CoarseConfig config;
    const auto found = CoarseAlign(CoarseQuery(structure, config), structure, YawWindow{});
    ASSERT_EQ(found.size(), static_cast<std::size_t>(config.TotalHypotheses()));
    const double step_rad = config.yaw_step_deg * std::numbers::pi / 180.0;
    for (std::size_t i = 0; i < found.size(); ++i) {
        EXPECT_EQ(found[i].score, found[0].score);
        EXPECT_NEAR(found[i].yaw_rad, 3.0 * step_rad * static_cast<double>(i), 1e-9) << i;
        EXPECT_LT(found[i].translation_m.norm(), 1e-9);
    }
}

TEST(PrepareScan, SplitsWallsFromGroundWithUnitNormalsFacingTheSensor) {
    ScanReductionConfig config;
    const PreparedScan scan = PrepareScan(test::SyntheticPlace(), config);
    ASSERT_GT(scan.structure->size(), 100u);
    ASSERT_GT(scan.ground->size(), 100u);
    for (std::size_t i = 0; i < scan.structure->size(); ++i) {
        const Eigen::Vector3f& n = scan.structure->normals()[i];
        EXPECT_NEAR(n.norm(), 1.0F, 1e-4F);
        EXPECT_LE(std::abs(n.z()), std::cos(45.0 * M_PI / 180.0) + 1e-6);
        EXPECT_LE(n.dot(scan.structure->points()[i]), 0.0F);
    }
    for (const auto& n : scan.ground->normals()) EXPECT_GT(std::abs(n.z()), 0.7F);
    EXPECT_LE(scan.structure->size(), static_cast<std::size_t>(config.max_structure_points));
    EXPECT_LE(scan.ground->size(), static_cast<std::size_t>(config.max_ground_points));
    EXPECT_GT(scan.MemoryBytes(), (scan.structure->size() + scan.ground->size()) * 24);
}

// PrepareScan's fast paths (the column grid's neighbours, the scatter in six sums, the closed-form
// smallest eigenvector) against the slow ones they replaced: nanoflann's k nearest, Eigen's outer
// products and Eigen's solver. Every kept point's distinctive flag must come out the same, its
// normal within 1e-5 of Eigen's (or, where the plane is ill-defined, an eigenvector of
// the smallest eigenvalue all the same).
TEST(PrepareScan, NormalsAndFlagsEqualTheTreeAndOuterProductPath) {
    const core::PointCloud scan = test::SyntheticPlace(4);
    const ScanReductionConfig config;
    const std::vector<Eigen::Vector3f> centroids = test::VoxelCentroids(scan, config);
    const PointTree tree(&centroids);
    std::vector<std::uint32_t> neighbors;
    const auto eigen_solver = [&](const Eigen::Vector3f& at, int k) {
        tree.Knn(at, k, neighbors);
        Eigen::Vector3d mean = Eigen::Vector3d::Zero();
        for (const auto i : neighbors) mean += centroids[i].cast<double>();
        mean /= static_cast<double>(neighbors.size());
        Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
        for (const auto i : neighbors) {
            const Eigen::Vector3d d = centroids[i].cast<double>() - mean;
            covariance += d * d.transpose();
        }
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
        solver.computeDirect(covariance);
        return solver;
    };
    const PreparedScan prepared = PrepareScan(scan, config);
    ASSERT_GT(prepared.structure->size(), 1000u);
    ASSERT_GT(prepared.ground->size(), 300u);
    std::size_t compared = 0;
    for (const SurfacePoints* surface : {prepared.structure.get(), prepared.ground.get()}) {
        for (std::size_t i = 0; i < surface->size(); ++i) {
            const Eigen::Vector3f& point = surface->points()[i];
            const auto solver = eigen_solver(point, config.normal_neighbors);
            Eigen::Vector3f normal = solver.eigenvectors().col(0).cast<float>();
            if (normal.dot(point) > 0.0F) normal = -normal;
            const Eigen::Vector3d& eigenvalues = solver.eigenvalues();
            const bool plane_defined = eigenvalues(1) - eigenvalues(0) > 1e-3 * eigenvalues(2);
            if (plane_defined) {
                ASSERT_LT((surface->normals()[i] - normal).norm(), 1e-5F) << i;
                ++compared;
            } else {
                const Eigen::Matrix3d scatter = solver.eigenvectors() * eigenvalues.asDiagonal() *
                                                solver.eigenvectors().transpose();
                const Eigen::Vector3d ours = surface->normals()[i].cast<double>();
                ASSERT_LT((scatter * ours - eigenvalues(0) * ours).norm(), 1e-5 * eigenvalues(2))
                    << i;
                ASSERT_LE(ours.dot(point.cast<double>()), 0.0) << i;
            }
        }
    }
    // Ill-defined planes are rare: most normals are compared with Eigen's.
    EXPECT_GT(compared, 9 * (prepared.structure->size() + prepared.ground->size()) / 10);
    for (std::size_t i = 0; i < prepared.structure->size(); ++i) {
        const Eigen::Vector3d eigenvalues =
            eigen_solver(prepared.structure->points()[i], config.distinctive_neighbors)
                .eigenvalues()
                .cwiseMax(0.0);
        const bool on_plane = eigenvalues(0) / eigenvalues.sum() <= config.max_plane_variation;
        ASSERT_EQ(prepared.structure_distinctive[i], on_plane ? 0 : 1) << i;
    }
}

TEST(PrepareScan, DropsNonFiniteAndOutOfRangePoints) {
    ScanReductionConfig config;
    core::PointCloud cloud = test::SyntheticPlace();
    const std::size_t valid = PrepareScan(cloud, config).usable_points;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    cloud.emplace_back(nan, 0.0F, 0.0F);
    cloud.emplace_back(5.0F, inf, 1.0F);
    cloud.emplace_back(0.5F, 0.0F, 0.0F);    // inside min_range_m
    cloud.emplace_back(500.0F, 0.0F, 0.0F);  // beyond max_range_m
    const PreparedScan scan = PrepareScan(cloud, config);
    EXPECT_EQ(scan.input_points, cloud.size());
    EXPECT_EQ(scan.usable_points, valid);
    for (const auto& p : scan.structure->points()) EXPECT_TRUE(p.allFinite());
}

// The view centre is the mean of the usable points, whatever else the scan holds: known answer.
TEST(PrepareScan, TheViewCentreIsTheMeanOfTheUsablePoints) {
    const ScanReductionConfig config;
    core::PointCloud cloud{{10.0F, 0.0F, 0.0F}, {20.0F, 4.0F, -2.0F}, {30.0F, -4.0F, 2.0F}};
    const float nan = std::numeric_limits<float>::quiet_NaN();
    cloud.emplace_back(nan, 0.0F, 0.0F);
    cloud.emplace_back(0.5F, 0.0F, 0.0F);     // inside min_range_m
    cloud.emplace_back(-500.0F, 0.0F, 0.0F);  // beyond max_range_m
    const Eigen::Vector3d expected(20.0, 0.0, 0.0);
    EXPECT_TRUE(ViewCentre(cloud, config).isApprox(expected, 1e-12));
    EXPECT_TRUE(PrepareScan(cloud, config).view_centre.isApprox(expected, 1e-12));
    // A scene ahead of the sensor (a narrow field of view) is looked at ahead.
    core::PointCloud ahead = test::SyntheticPlace();
    std::erase_if(ahead, [](const Eigen::Vector3f& p) { return p.x() < 1.0F; });
    EXPECT_GT(PrepareScan(ahead, config).view_centre.x(), 5.0);
    EXPECT_TRUE(ViewCentre({}, config).hasNaN());
    EXPECT_TRUE(PrepareScan(core::PointCloud(10, Eigen::Vector3f::Constant(nan)), config)
                    .view_centre.hasNaN());
}

TEST(PrepareScan, DegenerateScansGiveAlmostNothingAndNoCrash) {
    ScanReductionConfig config;
    EXPECT_EQ(PrepareScan({}, config).structure->size(), 0u);
    const core::PointCloud same(1000, Eigen::Vector3f(10.0F, 2.0F, 0.0F));
    const PreparedScan coincident = PrepareScan(same, config);
    EXPECT_EQ(coincident.usable_points, 1000u);
    EXPECT_EQ(coincident.structure->size() + coincident.ground->size(), 0u);
    const core::PointCloud nans(100, Eigen::Vector3f::Constant(std::nanf("")));
    EXPECT_EQ(PrepareScan(nans, config).usable_points, 0u);
}

}  // namespace
}  // namespace lidarloop::registration
