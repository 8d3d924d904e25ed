// The stock picture's canvas (board/sim/rgb_image.hpp): three bytes a pixel, rows top down, filled
// with the background; a pixel or a rectangle that runs off the edge is clipped, not written
// elsewhere.
#include <cstdint>
#include <vector>

#include "board/sim/rgb_image.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::board::sim;

namespace {
constexpr Rgb kWhite{255, 255, 255};
constexpr Rgb kRed{200, 10, 20};
}  // namespace

TEST_GROUP(RgbImage){};

TEST(RgbImage, StartsAsTheBackgroundThreeBytesAPixel) {
  const RgbImage image(4, 3, kWhite);
  CHECK_EQUAL(4, image.width());
  CHECK_EQUAL(3, image.height());
  CHECK_EQUAL(36U, image.bytes().size());
  for (const std::uint8_t byte : image.bytes()) {
    CHECK_EQUAL(255, byte);
  }
}

TEST(RgbImage, APixelLandsAtItsRowFromTheTop) {
  RgbImage image(4, 3, kWhite);
  image.set(1, 2, kRed);
  CHECK(image.at(1, 2) == kRed);
  CHECK(image.at(2, 1) == kWhite);
  const std::size_t at = 3 * (2 * 4 + 1);
  CHECK_EQUAL(200, image.bytes()[at]);
  CHECK_EQUAL(10, image.bytes()[at + 1]);
  CHECK_EQUAL(20, image.bytes()[at + 2]);
}

TEST(RgbImage, PixelsOffTheEdgeAreNotDrawnAnywhere) {
  RgbImage image(4, 3, kWhite);
  const std::vector<std::uint8_t> before = image.bytes();
  image.set(-1, 0, kRed);
  image.set(4, 0, kRed);  // would wrap onto the next row's first pixel
  image.set(0, -1, kRed);
  image.set(0, 3, kRed);
  CHECK(before == image.bytes());
}

TEST(RgbImage, ARectangleRunningOffTheEdgeIsClipped) {
  RgbImage image(4, 3, kWhite);
  image.fill(2, 1, 10, 10, kRed);
  int red = 0;
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 4; ++x) {
      const bool inside = x >= 2 && y >= 1;
      CHECK(image.at(x, y) == (inside ? kRed : kWhite));
      red += inside ? 1 : 0;
    }
  }
  CHECK_EQUAL(4, red);
}
