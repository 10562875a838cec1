#pragma once

// A 5x7 pixel font for the labels of images lidarloop draws itself (map.png): digits, lower-case
// letters (upper case is drawn lower case) and common punctuation; other characters draw as '?'.
// Internal; not installed as a public API promise.

#include <string_view>

#include "lidarloop/io/colour_map.hpp"
#include "lidarloop/io/png.hpp"

namespace lidarloop::io::detail {

/// Height of a glyph in font pixels; each is 5 wide with 1 of spacing.
inline constexpr int kGlyphHeight = 7;

/// Width in image pixels of `text` drawn at `scale` image pixels per font pixel.
int TextWidth(std::string_view text, int scale);

/// Draws `text` into an RGB `image` with its top-left corner at (x, y); what falls outside the
/// image is clipped.
void DrawText(Image& image, int x, int y, std::string_view text, int scale, Rgb colour);

}  // namespace lidarloop::io::detail
