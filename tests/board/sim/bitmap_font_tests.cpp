// The picture's bitmap font: the glyphs the labels need, where text is drawn and how wide.
#include "board/sim/bitmap_font.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::board::sim;

TEST_GROUP(BitmapFont){};

TEST(BitmapFont, HasTheDigitsSignsAndCapitalsTheLabelsUse) {
  for (const char c : std::string_view("0123456789.-+<> mABCDEFGHIJKLMNOPQRSTUVWXYZ")) {
    CHECK_TRUE(has_glyph(c));
  }
  CHECK_FALSE(has_glyph('q'));
}

TEST(BitmapFont, DrawsEachFontPixelAsAScaledSquareWithinItsWidth) {
  const Rgb white{255, 255, 255}, ink{0, 0, 0};
  RgbImage image(40, 20, white);
  draw_text(image, 2, 3, "-", 2, ink);
  // The minus is the fourth row's last four columns: x 2 + 2 * (1..4), y 3 + 2 * 3.
  CHECK_TRUE(image.at(4, 9) == ink);
  CHECK_TRUE(image.at(11, 10) == ink);
  CHECK_TRUE(image.at(2, 9) == white);
  CHECK_TRUE(image.at(4, 7) == white);
  LONGS_EQUAL(2 * (2 * 6 - 1), text_width("12", 2));
  LONGS_EQUAL(0, text_width("", 2));
}

TEST(BitmapFont, ACharacterWithoutAGlyphShowsAsABox) {
  const Rgb white{255, 255, 255}, ink{0, 0, 0};
  RgbImage image(10, 10, white);
  draw_text(image, 0, 0, "q", 1, ink);
  CHECK_TRUE(image.at(0, 0) == ink);
  CHECK_TRUE(image.at(4, 6) == ink);
  CHECK_TRUE(image.at(5, 0) == white);
}
