#include "lidarloop/registration/detail/fft2d.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <utility>

#include "lidarloop/core/detail/vector_clones.hpp"

namespace lidarloop::registration::detail {
namespace {

// exp(-2 pi i k / n) for k < 3n / 4, the twiddle factors of every stage of a length-n transform
// (the inverse uses their conjugates). Cached per thread for the last length.
struct Twiddles {
    int n = 0;
    std::vector<float> re, im;
};

const Twiddles& TwiddlesFor(int n) {
    thread_local Twiddles twiddles;
    if (twiddles.n != n) {
        const auto count = static_cast<std::size_t>(3 * n / 4);
        twiddles.re.resize(count);
        twiddles.im.resize(count);
        for (std::size_t k = 0; k < count; ++k) {
            const double angle = -2.0 * std::numbers::pi * static_cast<double>(k) / n;
            twiddles.re[k] = static_cast<float>(std::cos(angle));
            twiddles.im[k] = static_cast<float>(std::sin(angle));
        }
        twiddles.n = n;
    }
    return twiddles;
}

// The twiddles w, w^2, w^3 of one radix-4 butterfly, conjugated for the inverse.
struct QuarterTwiddles {
    float w1r, w1i, w2r, w2i, w3r, w3i;
};

// One radix-4 stage's butterflies on four runs of `run` contiguous values that share twiddles:
// a, b, c, d at p, p + L/4, p + L/2, p + 3L/4 of the current length L, out to 4p .. 4p + 3:
// y0 = (a + c) + (b + d), y1 = ((a - c) - j (b - d)) w, y2 = ((a + c) - (b + d)) w^2,
// y3 = ((a - c) + j (b - d)) w^3, with j = i forward and -i inverse (`j_sign`).
LIDARLOOP_ALWAYS_INLINE void Butterflies4(const float* __restrict ar, const float* __restrict ai,
                                          const float* __restrict br, const float* __restrict bi,
                                          const float* __restrict cr, const float* __restrict ci,
                                          const float* __restrict dr, const float* __restrict di,
                                          float* __restrict y0r, float* __restrict y0i,
                                          float* __restrict y1r, float* __restrict y1i,
                                          float* __restrict y2r, float* __restrict y2i,
                                          float* __restrict y3r, float* __restrict y3i,
                                          std::size_t run, const QuarterTwiddles& w, float j_sign) {
    for (std::size_t i = 0; i < run; ++i) {
        const float sum_ac_r = ar[i] + cr[i], sum_ac_i = ai[i] + ci[i];
        const float diff_ac_r = ar[i] - cr[i], diff_ac_i = ai[i] - ci[i];
        const float sum_bd_r = br[i] + dr[i], sum_bd_i = bi[i] + di[i];
        // j (b - d): i (u + iv) = -v + iu, times the sign.
        const float j_bd_r = -j_sign * (bi[i] - di[i]), j_bd_i = j_sign * (br[i] - dr[i]);
        y0r[i] = sum_ac_r + sum_bd_r;
        y0i[i] = sum_ac_i + sum_bd_i;
        const float t1r = diff_ac_r - j_bd_r, t1i = diff_ac_i - j_bd_i;
        y1r[i] = t1r * w.w1r - t1i * w.w1i;
        y1i[i] = t1r * w.w1i + t1i * w.w1r;
        const float t2r = sum_ac_r - sum_bd_r, t2i = sum_ac_i - sum_bd_i;
        y2r[i] = t2r * w.w2r - t2i * w.w2i;
        y2i[i] = t2r * w.w2i + t2i * w.w2r;
        const float t3r = diff_ac_r + j_bd_r, t3i = diff_ac_i + j_bd_i;
        y3r[i] = t3r * w.w3r - t3i * w.w3i;
        y3i[i] = t3r * w.w3i + t3i * w.w3r;
    }
}

// The last stage of a length that is an odd power of two: butterflies of length 2, y0 = a + b,
// y1 = a - b (the twiddle is 1).
LIDARLOOP_ALWAYS_INLINE void Butterflies2(const float* __restrict ar, const float* __restrict ai,
                                          const float* __restrict br, const float* __restrict bi,
                                          float* __restrict y0r, float* __restrict y0i,
                                          float* __restrict y1r, float* __restrict y1i,
                                          std::size_t run) {
    for (std::size_t i = 0; i < run; ++i) {
        y0r[i] = ar[i] + br[i];
        y0i[i] = ai[i] + bi[i];
        y1r[i] = ar[i] - br[i];
        y1i[i] = ai[i] - bi[i];
    }
}

// Transforms `count` sequences of length n (a power of two) at once, in place, unscaled: value e
// of sequence b is at [e * count + b]. Stockham, which sorts itself (no bit reversal), radix 4
// (and one radix-2 stage when n is an odd power of two): every butterfly combines runs of
// contiguous values under one set of twiddles, so the inner loop runs over whole rows and
// vectorises; radix 4 reads and writes the grid half as often as radix 2 did (docs/BENCHMARK.md).
// Eigen's FFT transforms one sequence at a time.
LIDARLOOP_VECTOR_CLONES
void TransformBatch(std::vector<float>& re, std::vector<float>& im, int n, std::size_t count,
                    bool inverse) {
    const Twiddles& twiddles = TwiddlesFor(n);
    const float sign = inverse ? -1.0F : 1.0F;
    thread_local std::vector<float> scratch_re, scratch_im;
    scratch_re.resize(re.size());
    scratch_im.resize(im.size());
    float *xr = re.data(), *xi = im.data(), *yr = scratch_re.data(), *yi = scratch_im.data();
    std::size_t stride = 1;  // n over the current length
    for (auto length = static_cast<std::size_t>(n); length >= 2;) {
        const std::size_t run = stride * count;
        if (length == 2) {
            Butterflies2(xr, xi, xr + run, xi + run, yr, yi, yr + run, yi + run, run);
            length = 1;
        } else {
            const std::size_t quarter = length / 4;
            for (std::size_t p = 0; p < quarter; ++p) {
                const std::size_t k = p * stride;
                const QuarterTwiddles w{twiddles.re[k],     sign * twiddles.im[k],
                                        twiddles.re[2 * k], sign * twiddles.im[2 * k],
                                        twiddles.re[3 * k], sign * twiddles.im[3 * k]};
                const auto in = [&](float* base, std::size_t q) {
                    return base + (p + q * quarter) * run;
                };
                const auto out = [&](float* base, std::size_t q) {
                    return base + (4 * p + q) * run;
                };
                Butterflies4(in(xr, 0), in(xi, 0), in(xr, 1), in(xi, 1), in(xr, 2), in(xi, 2),
                             in(xr, 3), in(xi, 3), out(yr, 0), out(yi, 0), out(yr, 1), out(yi, 1),
                             out(yr, 2), out(yi, 2), out(yr, 3), out(yi, 3), run, w, sign);
            }
            length = quarter;
            stride *= 4;
        }
        std::swap(xr, yr);
        std::swap(xi, yi);
    }
    // After an odd number of stages the result is in the scratch buffers: they trade places with
    // the caller's (same sizes) instead of being copied back.
    if (xr != re.data()) {
        re.swap(scratch_re);
        im.swap(scratch_im);
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
