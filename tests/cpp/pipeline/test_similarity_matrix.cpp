#include <random>

#include <gtest/gtest.h>

#include "lidarloop/core/descriptor.hpp"
#include "lidarloop/pipeline/descriptor_database.hpp"
#include "lidarloop/pipeline/similarity_matrix.hpp"
#include "pipeline/pipeline_test_utils.hpp"
#include "test_utils.hpp"

namespace lidarloop::pipeline {
namespace {

TEST(SimilarityMatrix, CondensedIndexingIsSymmetricWithZeroDiagonal) {
    SimilarityMatrix m(5);
    EXPECT_EQ(m.condensed().size(), 10U);
    float value = 1.0f;
    for (std::size_t i = 0; i < 5; ++i) {
        for (std::size_t j = i + 1; j < 5; ++j) m.set(i, j, value++);
    }
    for (std::size_t i = 0; i < 5; ++i) {
        EXPECT_EQ(m.at(i, i), 0.0f);
        for (std::size_t j = 0; j < 5; ++j) EXPECT_EQ(m.at(i, j), m.at(j, i));
    }
    EXPECT_EQ(m.at(0, 1), 1.0f);
    EXPECT_EQ(m.at(3, 4), 10.0f);
    EXPECT_THROW(m.at(5, 0), std::out_of_range);
}

TEST(SimilarityMatrix, ParallelEqualsSerialForHistograms) {
    core::DescriptorConfig config;
    config.method = core::Method::kHeight;  // test::HistogramDescriptor's
    config.histogram.bins = 30;
    DescriptorDatabase database(config);
    for (const auto& h : test::ClusteredHistograms(700, 30, 20, 4)) {
        database.Add(test::HistogramDescriptor(h), 0.0);
    }
    database.AddMissing(0.0);
    const SimilarityMatrix serial = ComputeSimilarityMatrix(database, Execution::kSerial);
    const SimilarityMatrix parallel = ComputeSimilarityMatrix(database, Execution::kParallel);
    EXPECT_EQ(serial.condensed(), parallel.condensed());
    for (std::size_t i = 0; i < 700; i += 37) {
        EXPECT_EQ(serial.at(i, 700), std::numeric_limits<float>::infinity());
        for (std::size_t j = 0; j < 700; j += 53) {
            EXPECT_EQ(serial.at(i, j), static_cast<float>(database.Distance(i, j)));
        }
    }
}

TEST(SimilarityMatrix, ParallelEqualsSerialForNdt) {
    core::DescriptorConfig config;
    config.method = core::Method::kNdt;
    DescriptorDatabase database(config);
    for (unsigned seed = 0; seed < 12; ++seed) {
        database.Add(pipeline::ComputeDescriptor(test::RandomCloud(3000, seed, 4.0f), config), 0.0);
    }
    const SimilarityMatrix serial = ComputeSimilarityMatrix(database, Execution::kSerial);
    EXPECT_EQ(serial.condensed(), ComputeSimilarityMatrix(database).condensed());
    EXPECT_GT(serial.at(0, 1), 0.0f);
}

}  // namespace
}  // namespace lidarloop::pipeline
