// The stock picture's layout, colours and legend, written through libpng.
#include "board/sim/stock_picture.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include <png.h>

#include "board/sim/bitmap_font.hpp"
#include "board/sim/height_field_view.hpp"
#include "board/sim/rgb_image.hpp"

namespace stencil::board::sim {
namespace {

constexpr Rgb kBackground{255, 255, 255};
constexpr Rgb kInk{30, 30, 30};
constexpr Rgb kGouge{220, 30, 30};
constexpr Rgb kOnPart{60, 175, 80};
constexpr Rgb kLeftLight{195, 215, 255};  // kLeftThicknessMm left: a trace, pale
constexpr Rgb kLeftDeep{20, 40, 165};      // kLeftFullMm or more left
constexpr int kTextScale = 2;

// The top view's and the 3-D view's places in the picture, and the legend's line under the first.
constexpr PanelRect kTopPanel{20, 40, 760, 560};
constexpr PanelRect kViewPanel{800, 40, 780, 660};
constexpr int kLegendY = 618;

std::uint8_t mix(std::uint8_t from, std::uint8_t to, double t) {
  return static_cast<std::uint8_t>(std::lround(from + (to - from) * t));
}

Rgb left_colour(double thickness_mm) {
  const double t = std::clamp((thickness_mm - kLeftThicknessMm) / (kLeftFullMm - kLeftThicknessMm), 0.0, 1.0);
  return {mix(kLeftLight.red, kLeftDeep.red, t), mix(kLeftLight.green, kLeftDeep.green, t),
          mix(kLeftLight.blue, kLeftDeep.blue, t)};
}

// Each cell's colour: its distance from the part says gouge or on the part; off the part, how much
// this tool could still remove there says stock left (blue, by its thickness) or, where that is
// under the tolerance (the floor, cusps, what no tool of this size reaches), a neutral grey, lighter
// where higher so that the floor and any uncut top stay apart. Stock left is measured by what the
// tool could remove rather than by the distance from the part: a cusp on the floor is 2 mm from the
// part but only its own height of work.
std::vector<Rgb> cell_colours(const SimResult& r) {
  double low = HUGE_VAL, high = -HUGE_VAL;
  for (const double h : r.stock_heights) {
    low = std::min(low, h);
    high = std::max(high, h);
  }
  std::vector<Rgb> colours(r.stock_heights.size());
  for (std::size_t i = 0; i < colours.size(); ++i) {
    const auto distance = static_cast<double>(r.signed_distance_mm[i]);
    const double left = i < r.unmachined_heights.size() ? r.unmachined_heights[i] : 0.0;
    if (distance < -kGougeToleranceMm) {
      colours[i] = kGouge;
    } else if (distance <= kOnPartMm) {
      colours[i] = kOnPart;
    } else if (left >= kLeftThicknessMm) {
      colours[i] = left_colour(left);
    } else {
      const auto grey = static_cast<std::uint8_t>(std::lround(150.0 + 70.0 * (high > low ? (r.stock_heights[i] - low) / (high - low) : 0.0)));
      colours[i] = {grey, grey, grey};
    }
  }
  return colours;
}

// The top view's pixels per cell and its top left corner, centred in its panel.
struct TopView {
  double px_per_cell;
  int x, y, width, height;
};

TopView top_view_of(int columns, int rows) {
  const double scale = std::min(static_cast<double>(kTopPanel.width) / columns, static_cast<double>(kTopPanel.height) / rows);
  const int width = static_cast<int>(std::lround(columns * scale)), height = static_cast<int>(std::lround(rows * scale));
  return {scale, kTopPanel.x + (kTopPanel.width - width) / 2, kTopPanel.y + (kTopPanel.height - height) / 2, width, height};
}

// Each pixel shows the cell under its centre, except that a gouge anywhere under the pixel shows:
// a shrunk picture must not hide one.
void draw_top_view(RgbImage& image, const SimResult& r, const std::vector<Rgb>& colours) {
  const TopView view = top_view_of(r.columns, r.rows);
  const auto cell = [&](double px, int count) { return std::clamp(static_cast<int>(std::floor(px / view.px_per_cell)), 0, count - 1); };
  for (int py = 0; py < view.height; ++py) {
    for (int px = 0; px < view.width; ++px) {
      const int from_top = cell(py + 0.5, r.rows);
      Rgb colour = colours[static_cast<std::size_t>(r.rows - 1 - from_top) * static_cast<std::size_t>(r.columns) +
                           static_cast<std::size_t>(cell(px + 0.5, r.columns))];
      for (int row = cell(py, r.rows); row <= cell(py + 1 - 1e-9, r.rows); ++row) {
        for (int column = cell(px, r.columns); column <= cell(px + 1 - 1e-9, r.columns); ++column) {
          if (colours[static_cast<std::size_t>(r.rows - 1 - row) * static_cast<std::size_t>(r.columns) +
                      static_cast<std::size_t>(column)] == kGouge) {
            colour = kGouge;
          }
        }
      }
      image.set(view.x + px, view.y + py, colour);
    }
  }
}

// Under the top view: a swatch for each kind of cell, then the blue scale with its ticks in mm.
void draw_legend(RgbImage& image) {
  int x = kTopPanel.x;
  const auto swatch = [&](Rgb colour, const char* label) {
    image.fill(x, kLegendY, 24, 14, colour);
    draw_text(image, x + 32, kLegendY, label, kTextScale, kInk);
    x += 32 + text_width(label, kTextScale) + 24;
  };
  swatch(kGouge, "GOUGE < -0.005");
  swatch(kOnPart, "ON THE PART +-0.05");
  swatch({185, 185, 185}, "< 0.05 LEFT TO CUT");

  const int bar_y = kLegendY + 34, bar_x = kTopPanel.x + text_width("STOCK LEFT", kTextScale) + 16, bar_width = 480;
  draw_text(image, kTopPanel.x, bar_y + 1, "STOCK LEFT", kTextScale, kInk);
  for (int i = 0; i < bar_width; ++i) {
    image.fill(bar_x + i, bar_y, 1, 16, left_colour(kLeftThicknessMm + (kLeftFullMm - kLeftThicknessMm) * i / (bar_width - 1)));
  }
  for (const auto& [mm, label] : std::array<std::pair<double, const char*>, 5>{
           {{kLeftThicknessMm, "0.05"}, {0.5, "0.5"}, {1.0, "1"}, {1.5, "1.5"}, {kLeftFullMm, "2 mm"}}}) {
    const int tick = bar_x + static_cast<int>(std::lround((mm - kLeftThicknessMm) / (kLeftFullMm - kLeftThicknessMm) * (bar_width - 1)));
    image.fill(tick, bar_y + 16, 2, 6, kInk);
    const int label_x = mm == kLeftFullMm ? tick : tick - text_width(label, kTextScale) / 2;
    draw_text(image, label_x, bar_y + 26, label, kTextScale, kInk);
  }
}

RgbImage draw_picture(const SimResult& r) {
  RgbImage image(kPictureWidthPx, kPictureHeightPx, kBackground);
  draw_text(image, kTopPanel.x, 12, "FROM ABOVE, AGAINST THE PART (mm)", kTextScale, kInk);
  draw_text(image, kViewPanel.x, 12, "THE MACHINED STOCK IN 3-D", kTextScale, kInk);
  draw_legend(image);
  if (r.columns <= 0 || r.rows <= 0) {
    return image;  // nothing was machined: the frame and its legend
  }
  const std::vector<Rgb> colours = cell_colours(r);
  draw_top_view(image, r, colours);
  double floor = HUGE_VAL;
  for (const double h : r.stock_heights) {
    floor = std::min(floor, h);
  }
  draw_height_field(image, kViewPanel, {r.columns, r.rows, r.cell_mm, floor, r.stock_heights, colours});
  return image;
}

}  // namespace

PixelPosition top_view_pixel(int columns, int rows, int column, int row) {
  const TopView view = top_view_of(columns, rows);
  return {view.x + static_cast<int>(std::floor((column + 0.5) * view.px_per_cell)),
          view.y + static_cast<int>(std::floor((rows - row - 0.5) * view.px_per_cell))};
}

bool write_picture_png(const std::string& path, const SimResult& result, std::string& error) {
  const std::size_t cells = static_cast<std::size_t>(std::max(result.columns, 0)) * static_cast<std::size_t>(std::max(result.rows, 0));
  if (result.stock_heights.size() != cells || result.signed_distance_mm.size() != cells) {
    error = path + ": the result's stock has " + std::to_string(cells) + " cells but " +
            std::to_string(result.stock_heights.size()) + " heights and " + std::to_string(result.signed_distance_mm.size()) +
            " signed distances";
    return false;
  }
  const RgbImage image = draw_picture(result);
  // libpng's simplified API: no time chunk is written, so the same result gives the same bytes.
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width());
  png.height = static_cast<png_uint_32>(image.height());
  png.format = PNG_FORMAT_RGB;
  if (png_image_write_to_file(&png, path.c_str(), 0, image.bytes().data(), 0, nullptr) == 0) {
    error = path;
    error.append(": cannot be written (").append(png.message).append(")");
    png_image_free(&png);
    return false;
  }
  return true;
}

}  // namespace stencil::board::sim
