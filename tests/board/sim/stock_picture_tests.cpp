// The stock picture: a PNG that decodes to the picture's size, each kind of cell in its colour where
// the top view puts it, the same bytes for the same result, and a path it cannot write named.
#include <cstdio>
#include <string>
#include <vector>

#include <png.h>
#include <unistd.h>

#include "board/sim/rgb_image.hpp"
#include "board/sim/stock_picture.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::board::sim;

namespace {

// Two columns, two rows of 1 mm, row-major with y rising: (0, 0) cut 0.1 mm into the part, (1, 0)
// on the part, (0, 1) with 0.8 mm left that this tool could remove, (1, 1) the floor 3 mm from the
// part, nothing there for this tool.
SimResult four_cells() {
  SimResult r;
  r.columns = 2;
  r.rows = 2;
  r.cell_mm = 1.0;
  r.part_heights = {1.0, 1.0, 1.0, 0.0};
  r.stock_heights = {0.9, 1.02, 1.8, 0.0};
  r.signed_distance_mm = {-0.1F, 0.02F, 0.8F, 2.0F};
  r.unmachined_heights = {0.0, 0.0, 0.8, 0.0};
  return r;
}

struct Decoded {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;
  [[nodiscard]] Rgb at(PixelPosition p) const {
    const std::size_t i = 3 * (static_cast<std::size_t>(p.y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(p.x));
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
};

// Reads a PNG back with libpng as 8-bit RGB; an empty picture when it does not decode.
Decoded read_png(const std::string& path) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  Decoded decoded;
  if (png_image_begin_read_from_file(&image, path.c_str()) == 0) {
    return decoded;
  }
  image.format = PNG_FORMAT_RGB;
  decoded.rgb.resize(PNG_IMAGE_SIZE(image));
  if (png_image_finish_read(&image, nullptr, decoded.rgb.data(), 0, nullptr) == 0) {
    png_image_free(&image);
    return {};
  }
  decoded.width = static_cast<int>(image.width);
  decoded.height = static_cast<int>(image.height);
  return decoded;
}

// The file's bytes (stdio: GCC 12 warns of a null dereference inside istreambuf_iterator).
std::string bytes_of(const std::string& path) {
  std::string bytes;
  std::FILE* in = std::fopen(path.c_str(), "rb");
  if (in == nullptr) {
    return bytes;
  }
  char block[4096];
  for (std::size_t n = 0; (n = std::fread(block, 1, sizeof block, in)) > 0;) {
    bytes.append(block, n);
  }
  std::fclose(in);
  return bytes;
}

bool reddish(Rgb c) { return c.red > 180 && c.green < 80 && c.blue < 80; }
bool greenish(Rgb c) { return c.green > c.red + 60 && c.green > c.blue + 60; }
bool bluish(Rgb c) { return c.blue > c.red + 30 && c.blue > c.green + 20; }
bool grey(Rgb c) { return c.red == c.green && c.green == c.blue && c.red > 100 && c.red < 240; }

}  // namespace

TEST_GROUP(StockPicture) {
  std::string folder;
  void setup() override {
    char name[] = "/tmp/stock_picture_tests.XXXXXX";
    const char* made = mkdtemp(name);
    CHECK(made != nullptr);
    folder = made;
  }
  void teardown() override {
    std::remove((folder + "/a.png").c_str());
    std::remove((folder + "/b.png").c_str());
    rmdir(folder.c_str());
  }
};

TEST(StockPicture, DecodesAsAPngOfThePicturesSize) {
  std::string error;
  CHECK_TRUE(write_picture_png(folder + "/a.png", four_cells(), error));
  const Decoded picture = read_png(folder + "/a.png");
  LONGS_EQUAL(kPictureWidthPx, picture.width);
  LONGS_EQUAL(kPictureHeightPx, picture.height);
}

TEST(StockPicture, EachCellShowsInTheColourOfWhatItMeansForTheJob) {
  std::string error;
  CHECK_TRUE(write_picture_png(folder + "/a.png", four_cells(), error));
  const Decoded picture = read_png(folder + "/a.png");
  CHECK_TRUE(reddish(picture.at(top_view_pixel(2, 2, 0, 0))));   // gouged
  CHECK_TRUE(greenish(picture.at(top_view_pixel(2, 2, 1, 0))));  // on the part
  CHECK_TRUE(bluish(picture.at(top_view_pixel(2, 2, 0, 1))));    // left, this tool could cut it
  CHECK_TRUE(grey(picture.at(top_view_pixel(2, 2, 1, 1))));      // floor, nothing to cut
}

TEST(StockPicture, RowsRunUpThePictureAsYRunsUpTheWorld) {
  const PixelPosition first_row = top_view_pixel(2, 2, 0, 0), second_row = top_view_pixel(2, 2, 0, 1);
  CHECK_TRUE(second_row.y < first_row.y);
  LONGS_EQUAL(first_row.x, second_row.x);
  CHECK_TRUE(top_view_pixel(2, 2, 1, 0).x > first_row.x);
}

TEST(StockPicture, MoreStockLeftIsADeeperBlue) {
  SimResult r = four_cells();
  std::string error;
  CHECK_TRUE(write_picture_png(folder + "/a.png", r, error));
  r.unmachined_heights[2] = 1.9;
  r.signed_distance_mm[2] = 1.9F;
  CHECK_TRUE(write_picture_png(folder + "/b.png", r, error));
  const Rgb less = read_png(folder + "/a.png").at(top_view_pixel(2, 2, 0, 1));
  const Rgb more = read_png(folder + "/b.png").at(top_view_pixel(2, 2, 0, 1));
  CHECK_TRUE(bluish(more));
  CHECK_TRUE(more.red + more.green + more.blue < less.red + less.green + less.blue);
}

TEST(StockPicture, StockNoToolCouldRemoveIsNotShownAsLeft) {
  SimResult r = four_cells();
  r.unmachined_heights[2] = 0.0;  // the same 0.8 mm, out of this tool's reach
  std::string error;
  CHECK_TRUE(write_picture_png(folder + "/a.png", r, error));
  CHECK_TRUE(grey(read_png(folder + "/a.png").at(top_view_pixel(2, 2, 0, 1))));
}

TEST(StockPicture, ACuspThinnerThanTheToleranceFarFromThePartIsNotShownAsLeft) {
  SimResult r = four_cells();
  r.stock_heights[3] = 0.04;  // the floor, 2 mm or more from the part, with a cusp of 0.04 mm on it
  r.unmachined_heights[3] = 0.04;
  std::string error;
  CHECK_TRUE(write_picture_png(folder + "/a.png", r, error));
  CHECK_TRUE(grey(read_png(folder + "/a.png").at(top_view_pixel(2, 2, 1, 1))));
  r.unmachined_heights[3] = 0.06;
  CHECK_TRUE(write_picture_png(folder + "/a.png", r, error));
  CHECK_TRUE(bluish(read_png(folder + "/a.png").at(top_view_pixel(2, 2, 1, 1))));
}

TEST(StockPicture, TheSameResultGivesTheSameBytes) {
  std::string error;
  CHECK_TRUE(write_picture_png(folder + "/a.png", four_cells(), error));
  CHECK_TRUE(write_picture_png(folder + "/b.png", four_cells(), error));
  const std::string a = bytes_of(folder + "/a.png");
  CHECK_TRUE(a.size() > 8);
  CHECK_TRUE(a == bytes_of(folder + "/b.png"));
}

TEST(StockPicture, APathItCannotWriteIsNamed) {
  const std::string path = folder + "/no such folder/picture.png";
  std::string error;
  CHECK_FALSE(write_picture_png(path, four_cells(), error));
  CHECK_TRUE(error.find(path) != std::string::npos);
}

TEST(StockPicture, AResultWithoutADistanceForEachCellIsRefused) {
  SimResult r = four_cells();
  r.signed_distance_mm.pop_back();
  std::string error;
  CHECK_FALSE(write_picture_png(folder + "/a.png", r, error));
  CHECK_TRUE(error.find("3 signed distances") != std::string::npos);
}
