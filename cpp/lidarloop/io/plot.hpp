#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace lidarloop::io {

/// One curve of a plot.
struct PlotSeries {
    enum class Style { kLines, kSteps, kPoints, kBoxes };
    std::string title;
    std::vector<double> x;
    std::vector<double> y;
    Style style = Style::kLines;
};

/// A 2-D plot, drawn by gnuplot (Debian's gnuplot-nox) into a PNG.
struct Plot {
    std::string title;
    std::string x_label;
    std::string y_label;
    std::vector<PlotSeries> series;
    bool x_log = false;
    /// Axis ranges; min >= max leaves gnuplot's automatic range.
    double x_min = 0.0, x_max = 0.0, y_min = 0.0, y_max = 0.0;
    std::vector<double> vertical_lines;  ///< e.g. a chosen threshold
    bool equal_axes = false;             ///< one metre is as long on both axes (maps)
    /// Colours of the series by index ("#1b9e77", "red"); missing or empty: gnuplot's sequence.
    std::vector<std::string> colors;
};

/// True when a gnuplot executable is on PATH.
bool GnuplotAvailable();

/// Renders `plot` to `png` (1000x700) and keeps the gnuplot script with its data beside it
/// (`png` with extension .gp) so that a user can restyle the figure. Series without points are
/// left out; a plot with no points at all is drawn empty, marked "no data". Throws WriteError
/// when gnuplot is missing or fails.
void RenderPlot(const std::filesystem::path& png, const Plot& plot);

/// The gnuplot script RenderPlot runs (data inline), for tests and for the .gp file.
std::string GnuplotScript(const std::filesystem::path& png, const Plot& plot);

}  // namespace lidarloop::io
