#include "lidarloop/registration/detail/fft2d.hpp"

#include <unsupported/Eigen/FFT>

namespace lidarloop::registration::detail {
namespace {

// Transforms every row, then every column; Eigen's FFT object caches its twiddle factors, so
// each thread keeps one.
void Transform2d(std::vector<std::complex<float>>& grid, int n, bool inverse) {
    thread_local Eigen::FFT<float> fft;
    thread_local std::vector<std::complex<float>> in, out;
    const auto size = static_cast<std::size_t>(n);
    in.resize(size);
    out.resize(size);
    auto run = [&] { inverse ? fft.inv(out, in) : fft.fwd(out, in); };
    for (std::size_t row = 0; row < size; ++row) {
        std::copy_n(grid.begin() + static_cast<std::ptrdiff_t>(row * size), size, in.begin());
        run();
        std::copy(out.begin(), out.end(), grid.begin() + static_cast<std::ptrdiff_t>(row * size));
    }
    for (std::size_t col = 0; col < size; ++col) {
        for (std::size_t row = 0; row < size; ++row) in[row] = grid[row * size + col];
        run();
        for (std::size_t row = 0; row < size; ++row) grid[row * size + col] = out[row];
    }
}

}  // namespace

void Fft2dInverseRows(std::vector<std::complex<float>>& grid, int n, const std::vector<int>& rows) {
    thread_local Eigen::FFT<float> fft;
    thread_local std::vector<std::complex<float>> in, out;
    const auto size = static_cast<std::size_t>(n);
    in.resize(size);
    out.resize(size);
    for (std::size_t col = 0; col < size; ++col) {
        for (std::size_t row = 0; row < size; ++row) in[row] = grid[row * size + col];
        fft.inv(out, in);
        for (std::size_t row = 0; row < size; ++row) grid[row * size + col] = out[row];
    }
    for (const int row : rows) {
        const auto begin = grid.begin() + static_cast<std::ptrdiff_t>(row) * n;
        std::copy_n(begin, size, in.begin());
        fft.inv(out, in);
        std::copy(out.begin(), out.end(), begin);
    }
}

void Fft2dForwardRealPair(const std::vector<float>& a, const std::vector<float>& b, int n,
                          std::vector<std::complex<float>>& spectrum_a,
                          std::vector<std::complex<float>>& spectrum_b) {
    const auto size = static_cast<std::size_t>(n);
    std::vector<std::complex<float>> packed(size * size);
    for (std::size_t i = 0; i < packed.size(); ++i) packed[i] = {a[i], b[i]};
    Transform2d(packed, n, false);
    spectrum_a.resize(packed.size());
    spectrum_b.resize(packed.size());
    for (std::size_t row = 0; row < size; ++row) {
        const std::size_t mirrored_row = (size - row) % size;
        for (std::size_t col = 0; col < size; ++col) {
            const std::complex<float> z = packed[row * size + col];
            const std::complex<float> mirrored =
                std::conj(packed[mirrored_row * size + (size - col) % size]);
            spectrum_a[row * size + col] = 0.5F * (z + mirrored);
            spectrum_b[row * size + col] = std::complex<float>(0.0F, -0.5F) * (z - mirrored);
        }
    }
}

void Fft2dForward(std::vector<std::complex<float>>& grid, int n) { Transform2d(grid, n, false); }
void Fft2dInverse(std::vector<std::complex<float>>& grid, int n) { Transform2d(grid, n, true); }

}  // namespace lidarloop::registration::detail
