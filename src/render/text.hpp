#pragma once
// Labels on pictures: a built-in 5×7 pixel font (no font files), drawn at an integer scale.
// Covers digits, + - = . , ( ) / and space, the letters a–z and A–Z, and µ, Δ, Å, ° (UTF-8);
// any other character is drawn as an open box.
#include <string>

#include "render/image.hpp"

namespace ibrod::render {

/// Glyph cell: 5×7 pixels plus 1 column of spacing, times `scale`.
inline constexpr int kGlyphW = 5, kGlyphH = 7, kGlyphAdvance = 6;

/// Width in pixels of `utf8` drawn at `scale` (kGlyphAdvance · scale per character, less the
/// trailing space).
int text_width(const std::string& utf8, int scale);

/// Draws `utf8` with its top-left corner at (x, y), each font pixel a scale × scale block of
/// `colour`; pixels outside the image are skipped.
void draw_text(Image& img, int x, int y, const std::string& utf8, int scale, Rgb colour);

}  // namespace ibrod::render
