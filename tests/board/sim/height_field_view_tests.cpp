// The shaded oblique view of the machined stock (board/sim/height_field_view): drawn only inside its
// panel, as large as fits, each cell's top in its own colour (shaded, never another hue) with grey
// sides, and a tall cell hiding what is behind it rather than being overdrawn.
#include <vector>

#include "board/sim/height_field_view.hpp"
#include "board/sim/rgb_image.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::board::sim;

namespace {

constexpr Rgb kBackground{255, 255, 255};
constexpr Rgb kRed{255, 0, 0};
constexpr Rgb kBlue{0, 0, 255};

struct Counts {
  int outside_panel_drawn = 0, inside_drawn = 0, reddish = 0, bluish = 0, grey = 0;
};

Counts count(const RgbImage& image, const PanelRect& panel) {
  Counts c;
  for (int y = 0; y < image.height(); ++y) {
    for (int x = 0; x < image.width(); ++x) {
      const Rgb p = image.at(x, y);
      if (p == kBackground) {
        continue;
      }
      const bool inside = x >= panel.x && x < panel.x + panel.width && y >= panel.y && y < panel.y + panel.height;
      (inside ? c.inside_drawn : c.outside_panel_drawn) += 1;
      if (p.red > 0 && p.green == 0 && p.blue == 0) {
        ++c.reddish;
      } else if (p.blue > 0 && p.red == 0 && p.green == 0) {
        ++c.bluish;
      } else if (p.red == p.green && p.green == p.blue) {
        ++c.grey;
      }
    }
  }
  return c;
}

}  // namespace

TEST_GROUP(HeightFieldView){};

TEST(HeightFieldView, DrawsAFlatStockInsideItsPanelOnlyInItsColourAndGreySides) {
  const std::vector<double> heights(16, 5.0);
  const std::vector<Rgb> colours(16, kRed);
  const HeightField field{4, 4, 1.0, 0.0, heights, colours};
  RgbImage image(200, 120, kBackground);
  const PanelRect panel{20, 10, 100, 80};
  draw_height_field(image, panel, field);
  const Counts c = count(image, panel);
  CHECK_EQUAL(0, c.outside_panel_drawn);
  // As large as fits: most of the panel is the stock.
  CHECK(c.inside_drawn > panel.width * panel.height / 3);
  CHECK(c.reddish > 0);
  CHECK(c.grey > 0);
  CHECK_EQUAL(c.inside_drawn, c.reddish + c.grey);
}

TEST(HeightFieldView, TheTopHidesTheSidesBehindIt) {
  // A thin slab seen from above: its top covers the back and the far sides, so nearly all of it is
  // the top's colour and only the two near sides show grey.
  const std::vector<double> heights(64, 0.5);
  const std::vector<Rgb> colours(64, kRed);
  const HeightField field{8, 8, 1.0, 0.0, heights, colours};
  RgbImage image(200, 200, kBackground);
  const PanelRect panel{0, 0, 200, 200};
  draw_height_field(image, panel, field);
  const Counts c = count(image, panel);
  CHECK(c.reddish > 4 * c.grey);
}

TEST(HeightFieldView, ATallCellAtTheFrontIsSeenInItsOwnColour) {
  // A tall blue column at the front-left corner (x 0, y 0: nearest the eye), low red cells elsewhere.
  std::vector<double> heights(16, 1.0);
  std::vector<Rgb> colours(16, kRed);
  heights[0] = 8.0;
  colours[0] = kBlue;
  const HeightField field{4, 4, 1.0, 0.0, heights, colours};
  RgbImage image(200, 200, kBackground);
  const PanelRect panel{0, 0, 200, 200};
  draw_height_field(image, panel, field);
  const Counts c = count(image, panel);
  CHECK(c.bluish > 0);
  CHECK(c.reddish > 0);
  CHECK_EQUAL(0, c.outside_panel_drawn);
}
