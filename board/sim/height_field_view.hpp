// A shaded oblique view of a height field: the machined stock seen from the front left and above,
// each cell in its own colour, lit by a fixed light (Lambert) and with hidden surfaces removed by a
// depth buffer. A small software rasterizer of our own: the picture is the only 3-D drawing the
// simulation makes, and a graphics library would cost more than these hundred lines.
#pragma once

#include <span>

#include "board/sim/rgb_image.hpp"

namespace stencil::board::sim {

// `columns` x `rows` cells of `cell_mm`, row-major with y rising, each with its top's height (mm)
// and its colour; the stock's sides are drawn down to `floor_mm`.
struct HeightField {
  int columns;
  int rows;
  double cell_mm;
  double floor_mm;
  std::span<const double> heights;
  std::span<const Rgb> colours;
};

// A rectangle of the picture, pixels.
struct PanelRect {
  int x, y, width, height;
};

// Draws `field` as large as fits in `panel` (true scale in every axis), over what is there.
void draw_height_field(RgbImage& image, const PanelRect& panel, const HeightField& field);

}  // namespace stencil::board::sim
