#pragma once
// A 5 x 7 pixel bitmap font (ASCII letters, digits and the punctuation of numbers, titles and
// file names), drawn on the CPU into an Image at an integer scale.

#include <string_view>

#include "focal/render/render.h"

namespace focal::render_detail {

constexpr int kGlyphWidth = 5;
constexpr int kGlyphHeight = 7;
constexpr int kGlyphAdvance = 6;  ///< glyph width and one column of spacing

/// Width in pixels of `text` drawn at `scale` (no trailing spacing).
[[nodiscard]] int text_width(std::string_view text, int scale);

/// Draws `text` with its top-left corner at (x, y); pixels outside the image are clipped.
/// Characters without a glyph are drawn as '?'.
void draw_text(Image& image, int x, int y, std::string_view text, int scale, Rgb colour);

}  // namespace focal::render_detail
