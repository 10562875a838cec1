#include "lidarloop/io/map_image.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>

#include "lidarloop/core/error.hpp"
#include "lidarloop/io/colour_map.hpp"
#include "lidarloop/io/detail/bitmap_font.hpp"
#include "lidarloop/io/map_files.hpp"

namespace lidarloop::io {
namespace {

constexpr int kMargin = 16;
constexpr int kGap = 24;        // between panels
constexpr int kTitleScale = 3;  // font pixels of titles
constexpr int kLabelScale = 2;  // of labels
constexpr double kQuantile = 0.001;
constexpr Rgb kBlack{0, 0, 0};
constexpr Rgb kFrame{160, 160, 160};

// What the panels show: [x0, x1] x [y0, y1] at m_per_px, w x h pixels.
struct Extent {
    double x0 = -10.0, y0 = -10.0, x1 = 10.0, y1 = 10.0;
    double m_per_px = 1.0;
    int w = 1, h = 1;
};

// Point counts and the sum of their time fractions per pixel of one panel.
struct Raster {
    std::vector<std::uint32_t> count;
    std::vector<double> time_sum;
};

std::pair<double, double> QuantileRange(std::vector<double> values) {
    const auto last = values.size() - 1;
    const auto low = static_cast<std::ptrdiff_t>(std::floor(kQuantile * static_cast<double>(last)));
    const auto high =
        static_cast<std::ptrdiff_t>(std::ceil((1.0 - kQuantile) * static_cast<double>(last)));
    std::nth_element(values.begin(), values.begin() + low, values.end());
    const double a = values[static_cast<std::size_t>(low)];
    std::nth_element(values.begin(), values.begin() + high, values.end());
    return {a, values[static_cast<std::size_t>(high)]};
}

Extent FindExtent(const std::vector<MapPanel>& panels, int panel_pixels) {
    std::vector<double> xs, ys;
    for (const MapPanel& panel : panels) {
        for (const core::MapPoint& point : panel.map->points) {
            xs.push_back(point.position.x());
            ys.push_back(point.position.y());
        }
    }
    Extent e;
    if (!xs.empty()) {
        std::tie(e.x0, e.x1) = QuantileRange(std::move(xs));
        std::tie(e.y0, e.y1) = QuantileRange(std::move(ys));
    }
    // A margin of 2 %, and at least 1 m across.
    const double pad = 0.02 * std::max({e.x1 - e.x0, e.y1 - e.y0, 1.0});
    e.x0 -= pad, e.x1 += pad, e.y0 -= pad, e.y1 += pad;
    e.m_per_px = std::max(e.x1 - e.x0, e.y1 - e.y0) / panel_pixels;
    e.w = std::max(1, static_cast<int>(std::ceil((e.x1 - e.x0) / e.m_per_px)));
    e.h = std::max(1, static_cast<int>(std::ceil((e.y1 - e.y0) / e.m_per_px)));
    return e;
}

Raster Rasterise(const core::MapCloud& map, const Extent& e) {
    const auto pixels = static_cast<std::size_t>(e.w) * static_cast<std::size_t>(e.h);
    Raster raster{std::vector<std::uint32_t>(pixels, 0), std::vector<double>(pixels, 0.0)};
    for (const core::MapPoint& point : map.points) {
        const double u = std::floor((point.position.x() - e.x0) / e.m_per_px);
        const double v = std::floor((e.y1 - point.position.y()) / e.m_per_px);  // y up
        if (!(u >= 0 && v >= 0 && u < e.w && v < e.h)) continue;
        const auto at = static_cast<std::size_t>(v) * static_cast<std::size_t>(e.w) +
                        static_cast<std::size_t>(u);
        ++raster.count[at];
        raster.time_sum[at] += std::clamp(MapTimeFraction(map, point.time_s), 0.0, 1.0);
    }
    return raster;
}

// The count that gets full colour: the 99th percentile of the occupied pixels of all panels.
double FullCount(const std::vector<Raster>& rasters) {
    std::vector<std::uint32_t> counts;
    for (const Raster& raster : rasters) {
        for (const std::uint32_t count : raster.count) {
            if (count > 0) counts.push_back(count);
        }
    }
    if (counts.empty()) return 1.0;
    const auto at = static_cast<std::ptrdiff_t>(0.99 * static_cast<double>(counts.size() - 1));
    std::nth_element(counts.begin(), counts.begin() + at, counts.end());
    return std::max(2.0, static_cast<double>(counts[static_cast<std::size_t>(at)]));
}

void Set(Image& image, int x, int y, Rgb rgb) {
    if (x < 0 || y < 0 || x >= image.width || y >= image.height) return;
    const auto at = (static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) +
                     static_cast<std::size_t>(x)) *
                    3;
    for (int c = 0; c < 3; ++c) image.pixels[at + static_cast<std::size_t>(c)] = rgb[c];
}

void FillRect(Image& image, int x, int y, int w, int h, Rgb rgb) {
    for (int j = y; j < y + h; ++j) {
        for (int i = x; i < x + w; ++i) Set(image, i, j, rgb);
    }
}

void Frame(Image& image, int x, int y, int w, int h) {
    FillRect(image, x - 1, y - 1, w + 2, 1, kFrame);
    FillRect(image, x - 1, y + h, w + 2, 1, kFrame);
    FillRect(image, x - 1, y, 1, h, kFrame);
    FillRect(image, x + w, y, 1, h, kFrame);
}

void Paint(Image& image, const Raster& raster, const Extent& e, int x, int y, double full) {
    const double log_full = std::log1p(full);
    for (int v = 0; v < e.h; ++v) {
        for (int u = 0; u < e.w; ++u) {
            const auto at = static_cast<std::size_t>(v) * static_cast<std::size_t>(e.w) +
                            static_cast<std::size_t>(u);
            const std::uint32_t count = raster.count[at];
            if (count == 0) continue;
            const double alpha =
                0.15 + 0.85 * std::min(1.0, std::log1p(static_cast<double>(count)) / log_full);
            const Rgb colour = Viridis(raster.time_sum[at] / count);
            Rgb blended{};
            for (int c = 0; c < 3; ++c) {
                blended[c] = static_cast<std::uint8_t>(
                    std::lround(255.0 * (1.0 - alpha) + colour[c] * alpha));
            }
            Set(image, x + u, y + v, blended);
        }
    }
}

// 1, 2 or 5 times a power of ten, at most `target` metres.
double NiceLength(double target) {
    const double power = std::pow(10.0, std::floor(std::log10(target)));
    for (const double step : {5.0, 2.0}) {
        if (step * power <= target) return step * power;
    }
    return power;
}

std::string Metres(double value) {
    char text[32];
    std::snprintf(text, sizeof(text), "%g m", value);
    return text;
}

// Scale bar and colour bar at `y` under the panels, the extent under them.
void DrawLegend(Image& image, const Extent& e, int y) {
    const double length_m = NiceLength(0.3 * e.w * e.m_per_px);
    const int bar = static_cast<int>(std::lround(length_m / e.m_per_px));
    FillRect(image, kMargin, y + 5, bar, 4, kBlack);
    FillRect(image, kMargin, y, 2, 14, kBlack);
    FillRect(image, kMargin + bar - 2, y, 2, 14, kBlack);
    detail::DrawText(image, kMargin + bar + 10, y, Metres(length_m), kLabelScale, kBlack);
    const std::string first = "scan time: first", last = "last";
    int x = image.width - kMargin - detail::TextWidth(last, kLabelScale) - 200 - 20 -
            detail::TextWidth(first, kLabelScale);
    detail::DrawText(image, x, y, first, kLabelScale, kBlack);
    x += detail::TextWidth(first, kLabelScale) + 10;
    for (int i = 0; i < 200; ++i) FillRect(image, x + i, y, 1, 14, Viridis(i / 199.0));
    detail::DrawText(image, x + 210, y, last, kLabelScale, kBlack);
    char extent[160];
    std::snprintf(extent, sizeof(extent),
                  "top view, x %.0f..%.0f m, y %.0f..%.0f m; stronger colour: more points", e.x0,
                  e.x1, e.y0, e.y1);
    detail::DrawText(image, kMargin, y + 26, extent, kLabelScale, kBlack);
}

}  // namespace

Image MapTopView(const std::vector<MapPanel>& panels, int panel_pixels) {
    if (panels.empty()) throw core::ConfigError("a map image needs at least one map");
    for (const MapPanel& panel : panels) {
        if (panel.map == nullptr)
            throw core::ConfigError("map panel '" + panel.title + "' has no map");
    }
    if (panel_pixels < 50 || panel_pixels > 4000) {
        throw core::ConfigError("map panels must be 50 to 4000 pixels, got " +
                                std::to_string(panel_pixels));
    }
    const Extent e = FindExtent(panels, panel_pixels);
    std::vector<Raster> rasters;
    for (const MapPanel& panel : panels) rasters.push_back(Rasterise(*panel.map, e));
    const double full = FullCount(rasters);
    const int n = static_cast<int>(panels.size());
    const int top = kMargin + detail::kGlyphHeight * kTitleScale + 12;
    Image image;
    image.channels = 3;
    image.width = std::max(2 * kMargin + n * e.w + (n - 1) * kGap, 700);
    image.height = top + e.h + 12 + 60;
    image.pixels.assign(static_cast<std::size_t>(image.width) * image.height * 3, 255);
    for (int k = 0; k < n; ++k) {
        const int x = kMargin + k * (e.w + kGap);
        detail::DrawText(image, x, kMargin, panels[k].title, kTitleScale, kBlack);
        Frame(image, x, top, e.w, e.h);
        Paint(image, rasters[k], e, x, top, full);
    }
    DrawLegend(image, e, top + e.h + 12);
    return image;
}

}  // namespace lidarloop::io
