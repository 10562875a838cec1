#pragma once

#include <complex>
#include <vector>

namespace lidarloop::registration::detail {

/// An n x n grid of complex numbers as two row-major planes, the real and the imaginary parts.
struct SplitGrid {
    std::vector<float> re, im;
};

/// In-place 2-D discrete Fourier transform of an n x n row-major grid, n a power of two (columns,
/// then rows; a batched radix-4 kernel checked against Eigen's FFT in the tests). The inverse is
/// scaled by 1 / n^2, so Inverse(Forward(x)) == x. Thread-safe.
void Fft2dForward(std::vector<std::complex<float>>& grid, int n);
void Fft2dInverse(std::vector<std::complex<float>>& grid, int n);
/// The forward transforms of two real n x n images at the cost of one complex transform: `a` is
/// packed into the real part, `b` into the imaginary part, and the spectra are separated by their
/// conjugate symmetry (A[k] = (Z[k] + conj(Z[-k])) / 2, B[k] = (Z[k] - conj(Z[-k])) / 2i).
void Fft2dForwardRealPair(const std::vector<float>& a, const std::vector<float>& b, int n,
                          std::vector<std::complex<float>>& spectrum_a,
                          std::vector<std::complex<float>>& spectrum_b);
/// The inverse transform computed only for the rows listed in `rows` (columns first, then those
/// rows), into `narrow` column by column: the value at (x, rows[j]) is at [x * rows.size() + j].
/// `grid` is left with partial results. For correlations read in a band of rows.
void Fft2dInverseRows(SplitGrid& grid, int n, const std::vector<int>& rows, SplitGrid& narrow);

}  // namespace lidarloop::registration::detail
