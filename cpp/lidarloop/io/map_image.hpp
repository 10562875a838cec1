#pragma once

#include <string>
#include <vector>

#include "lidarloop/core/point_map.hpp"
#include "lidarloop/io/png.hpp"

namespace lidarloop::io {

/// One map of a MapTopView.
struct MapPanel {
    std::string title;                    ///< drawn above the panel
    const core::MapCloud* map = nullptr;  ///< not null
};

/// Longer side of a map panel, pixels.
inline constexpr int kMapPanelPixels = 800;

/// The top view (x right, y up, metres) of maps side by side, at one scale over one extent: the
/// 0.1 % to 99.9 % quantiles of all the maps' x and y (a few far points cannot shrink the rest;
/// points outside are left out). A pixel is white where no point falls, else the Viridis colour of
/// the mean time of its points (MapTimeFraction), blended over white by its point count on a log
/// scale common to all panels, so that walls, which stack points, stand out of the ground. Titles
/// above; a scale bar in metres, the extent and a colour bar (first to last scan) below. RGB.
/// Throws core::ConfigError for no panels, a null map or `panel_pixels` outside [50, 4000].
Image MapTopView(const std::vector<MapPanel>& panels, int panel_pixels = kMapPanelPixels);

}  // namespace lidarloop::io
