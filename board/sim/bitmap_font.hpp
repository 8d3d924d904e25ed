// A 5x7 bitmap font of our own for the stock picture's labels: digits, capitals, a few signs and
// 'm' for millimetres. Our own rather than a font library: a few dozen glyphs cost less than a
// dependency (FreeType and a font file) on every machine that runs the simulation.
#pragma once

#include <string_view>

#include "board/sim/rgb_image.hpp"

namespace stencil::board::sim {

inline constexpr int kGlyphWidth = 5;   // pixels at scale 1
inline constexpr int kGlyphHeight = 7;
inline constexpr int kGlyphAdvance = 6;  // the glyph and a column of space

// Whether `c` has a glyph; one without is drawn as a filled box, so that a missing one shows.
[[nodiscard]] bool has_glyph(char c);

// Draws `text` with its top left corner at (x, y), each font pixel `scale` pixels square.
void draw_text(RgbImage& image, int x, int y, std::string_view text, int scale, Rgb colour);

// How wide `text` is drawn at `scale`, pixels.
[[nodiscard]] int text_width(std::string_view text, int scale);

}  // namespace stencil::board::sim
