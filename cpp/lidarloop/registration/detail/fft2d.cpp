#include "lidarloop/registration/detail/fft2d.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <utility>

#include "lidarloop/core/detail/vector_clones.hpp"

namespace lidarloop::registration::detail {
namespace {

// exp(-2 pi i k / n) for k < n / 2, the twiddle factors of every stage of a length-n transform
// (the inverse uses their conjugates). Cached per thread for the last length.
struct Twiddles {
    int n = 0;
    std::vector<float> re, im;
};

const Twiddles& TwiddlesFor(int n) {
    thread_local Twiddles twiddles;
    if (twiddles.n != n) {
        const auto half = static_cast<std::size_t>(n / 2);
        twiddles.re.resize(half);
        twiddles.im.resize(half);
        for (std::size_t k = 0; k < half; ++k) {
            const double angle = -2.0 * std::numbers::pi * static_cast<double>(k) / n;
            twiddles.re[k] = static_cast<float>(std::cos(angle));
            twiddles.im[k] = static_cast<float>(std::sin(angle));
        }
        twiddles.n = n;
    }
    return twiddles;
}

// One stage's butterflies on two runs of `run` contiguous values that share the twiddle w:
// y0 = a + b, y1 = (a - b) w.
void Butterflies(const float* __restrict ar, const float* __restrict ai, const float* __restrict br,
                 const float* __restrict bi, float* __restrict y0r, float* __restrict y0i,
                 float* __restrict y1r, float* __restrict y1i, std::size_t run, float wr,
                 float wi) {
    for (std::size_t i = 0; i < run; ++i) {
        const float dr = ar[i] - br[i];
        const float di = ai[i] - bi[i];
        y0r[i] = ar[i] + br[i];
        y0i[i] = ai[i] + bi[i];
        y1r[i] = dr * wr - di * wi;
        y1i[i] = dr * wi + di * wr;
    }
}

// Transforms `count` sequences of length n (a power of two) at once, in place, unscaled: value e
// of sequence b is at [e * count + b]. Radix-2 Stockham, which sorts itself (no bit reversal):
// every butterfly combines two runs of contiguous values under one twiddle factor, so the inner
// loop runs over whole rows and vectorises. Eigen's FFT transforms one sequence at a time.
LIDARLOOP_VECTOR_CLONES
void TransformBatch(std::vector<float>& re, std::vector<float>& im, int n, std::size_t count,
                    bool inverse) {
    const Twiddles& twiddles = TwiddlesFor(n);
    const float sign = inverse ? -1.0F : 1.0F;
    thread_local std::vector<float> scratch_re, scratch_im;
    scratch_re.resize(re.size());
    scratch_im.resize(im.size());
    float *xr = re.data(), *xi = im.data(), *yr = scratch_re.data(), *yi = scratch_im.data();
    std::size_t stride = 1;
    for (auto half = static_cast<std::size_t>(n / 2); half >= 1; half /= 2, stride *= 2) {
        const std::size_t run = stride * count;
        for (std::size_t p = 0; p < half; ++p) {
            Butterflies(xr + p * run, xi + p * run, xr + (p + half) * run, xi + (p + half) * run,
                        yr + 2 * p * run, yi + 2 * p * run, yr + (2 * p + 1) * run,
                        yi + (2 * p + 1) * run, run, twiddles.re[p * stride],
                        sign * twiddles.im[p * stride]);
        }
        std::swap(xr, yr);
        std::swap(xi, yi);
    }
    if (xr != re.data()) {
        std::copy_n(xr, re.size(), re.data());
        std::copy_n(xi, im.size(), im.data());
    }
}

// The transform of every row of the n x n grid: rows become columns, are transformed together,
// and go back.
void TransformRows(SplitGrid& grid, int n, bool inverse, float scale) {
    const auto size = static_cast<std::size_t>(n);
    thread_local SplitGrid transposed;
    transposed.re.resize(size * size);
    transposed.im.resize(size * size);
    for (std::size_t row = 0; row < size; ++row) {
        for (std::size_t col = 0; col < size; ++col) {
            transposed.re[col * size + row] = grid.re[row * size + col];
            transposed.im[col * size + row] = grid.im[row * size + col];
        }
    }
    TransformBatch(transposed.re, transposed.im, n, size, inverse);
    for (std::size_t row = 0; row < size; ++row) {
        for (std::size_t col = 0; col < size; ++col) {
            grid.re[row * size + col] = scale * transposed.re[col * size + row];
            grid.im[row * size + col] = scale * transposed.im[col * size + row];
        }
    }
}

void Transform2d(SplitGrid& grid, int n, bool inverse) {
    TransformBatch(grid.re, grid.im, n, static_cast<std::size_t>(n), inverse);
    const float scale = inverse ? 1.0F / static_cast<float>(n * n) : 1.0F;
    TransformRows(grid, n, inverse, scale);
}

SplitGrid Split(const std::vector<std::complex<float>>& grid) {
    SplitGrid split;
    split.re.resize(grid.size());
    split.im.resize(grid.size());
    for (std::size_t i = 0; i < grid.size(); ++i) {
        split.re[i] = grid[i].real();
        split.im[i] = grid[i].imag();
    }
    return split;
}

void Join(const SplitGrid& split, std::vector<std::complex<float>>& grid) {
    grid.resize(split.re.size());
    for (std::size_t i = 0; i < grid.size(); ++i) grid[i] = {split.re[i], split.im[i]};
}

void Transform2d(std::vector<std::complex<float>>& grid, int n, bool inverse) {
    SplitGrid split = Split(grid);
    Transform2d(split, n, inverse);
    Join(split, grid);
}

// Row `row` of the spectra of the two real images packed in `z` (a in the real part, b in the
// imaginary part), from z's row and its mirror (the row at -row, the columns reversed):
// A = (z + conj(z~)) / 2, B = (z - conj(z~)) / 2i. Written out, as std::complex's product checks
// for NaN and does not vectorise.
LIDARLOOP_VECTOR_CLONES
void SeparateRow(const SplitGrid& z, std::size_t row, std::size_t mirrored_row, std::size_t size,
                 std::vector<std::complex<float>>& spectrum_a,
                 std::vector<std::complex<float>>& spectrum_b) {
    const float* __restrict zr = z.re.data() + row * size;
    const float* __restrict zi = z.im.data() + row * size;
    const float* __restrict mr = z.re.data() + mirrored_row * size;
    const float* __restrict mi = z.im.data() + mirrored_row * size;
    std::complex<float>* __restrict out_a = spectrum_a.data() + row * size;
    std::complex<float>* __restrict out_b = spectrum_b.data() + row * size;
    for (std::size_t col = 0; col < size; ++col) {
        const std::size_t mirrored = (size - col) % size;
        out_a[col] = {0.5F * (zr[col] + mr[mirrored]), 0.5F * (zi[col] - mi[mirrored])};
        out_b[col] = {0.5F * (zi[col] + mi[mirrored]), -0.5F * (zr[col] - mr[mirrored])};
    }
}

}  // namespace

void Fft2dInverseRows(SplitGrid& grid, int n, const std::vector<int>& rows, SplitGrid& narrow) {
    const auto size = static_cast<std::size_t>(n);
    TransformBatch(grid.re, grid.im, n, size, true);
    // The listed rows only: gathered as columns of a narrow grid and transformed there.
    const std::size_t count = rows.size();
    narrow.re.resize(size * count);
    narrow.im.resize(size * count);
    const float scale = 1.0F / static_cast<float>(n * n);
    for (std::size_t j = 0; j < count; ++j) {
        const std::size_t offset = static_cast<std::size_t>(rows[j]) * size;
        for (std::size_t col = 0; col < size; ++col) {
            narrow.re[col * count + j] = scale * grid.re[offset + col];
            narrow.im[col * count + j] = scale * grid.im[offset + col];
        }
    }
    TransformBatch(narrow.re, narrow.im, n, count, true);
}

void Fft2dForwardRealPair(const std::vector<float>& a, const std::vector<float>& b, int n,
                          std::vector<std::complex<float>>& spectrum_a,
                          std::vector<std::complex<float>>& spectrum_b) {
    const auto size = static_cast<std::size_t>(n);
    thread_local SplitGrid packed;
    packed.re = a;
    packed.im = b;
    Transform2d(packed, n, false);
    spectrum_a.resize(size * size);
    spectrum_b.resize(size * size);
    for (std::size_t row = 0; row < size; ++row) {
        SeparateRow(packed, row, (size - row) % size, size, spectrum_a, spectrum_b);
    }
}

void Fft2dForward(std::vector<std::complex<float>>& grid, int n) { Transform2d(grid, n, false); }
void Fft2dInverse(std::vector<std::complex<float>>& grid, int n) { Transform2d(grid, n, true); }

}  // namespace lidarloop::registration::detail
