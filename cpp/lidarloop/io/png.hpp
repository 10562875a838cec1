#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

namespace lidarloop::io {

/// An 8-bit image, row-major, `channels` = 1 (grey) or 3 (RGB) bytes per pixel.
struct Image {
    int width = 0;
    int height = 0;
    int channels = 1;
    std::vector<std::uint8_t> pixels;
};

/// Writes `image` as PNG with libpng; WriteError when the file cannot be written, ConfigError
/// for an image whose size does not match its pixels.
void WritePng(const std::filesystem::path& file, const Image& image);

}  // namespace lidarloop::io
