#pragma once

#include <cstddef>
#include <span>
#include <vector>

namespace lidarloop::pipeline {

/// Röhling eq. (6) says W(G, H) = (1/b) * sum_k |C_G[k] - C_H[k]| with C the cumulative
/// histogram: an L1 distance. This store keeps the cumulative histograms of many scans as float
/// rows in one contiguous array, padded with zeros to a multiple of kLanes, so that a comparison
/// is one vectorised pass over two rows and no prefix sum is formed at query time.
/// 4 * stride bytes per scan (416 bytes at b = 100). Float rows hold each cumulative value to
/// 2^-24, so W is exact to ~1e-7, four orders below the thresholds in use (~1e-3).
class CumulativeHistograms {
public:
    static constexpr int kLanes = 8;

    /// `bins` in [1, 1'000'000]; throws core::ConfigError otherwise.
    explicit CumulativeHistograms(int bins);

    int bins() const { return bins_; }
    int stride() const { return stride_; }
    std::size_t size() const { return data_.size() / static_cast<std::size_t>(stride_); }

    /// The padded cumulative row of a normalised histogram (mass of size bins()).
    std::vector<float> MakeRow(std::span<const double> mass) const;
    /// Appends the histogram `mass`; returns its index.
    std::size_t Add(std::span<const double> mass);
    /// Appends a row made by MakeRow (or read back from a file).
    std::size_t AddRow(std::span<const float> row);

    const float* Row(std::size_t i) const { return data_.data() + i * stride_; }
    /// W between stored scans i and j.
    double Distance(std::size_t i, std::size_t j) const { return DistanceToRow(Row(i), j); }
    /// W between a query row (from MakeRow) and stored scan j.
    double DistanceToRow(const float* query_row, std::size_t j) const {
        return static_cast<double>(L1(query_row, Row(j), stride_)) / bins_;
    }
    const std::vector<float>& data() const { return data_; }

    /// Sum of |a_k - b_k| over `count` floats (a multiple of kLanes), in kLanes independent
    /// partial sums that the compiler keeps in vector registers.
    static float L1(const float* a, const float* b, int count);

private:
    int bins_;
    int stride_;
    std::vector<float> data_;
};

}  // namespace lidarloop::pipeline
