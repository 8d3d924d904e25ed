// An RGB picture in memory, 8 bits a channel, rows top down: what the stock picture is drawn into
// before it is written as PNG.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace stencil::board::sim {

struct Rgb {
  std::uint8_t red, green, blue;
  bool operator==(const Rgb&) const = default;
};

class RgbImage {
 public:
  RgbImage(int width, int height, Rgb background)
      : width_(width), height_(height), bytes_(3 * static_cast<std::size_t>(width) * static_cast<std::size_t>(height)) {
    fill(0, 0, width, height, background);
  }

  [[nodiscard]] int width() const { return width_; }
  [[nodiscard]] int height() const { return height_; }
  // Three bytes a pixel, row after row from the top.
  [[nodiscard]] const std::vector<std::uint8_t>& bytes() const { return bytes_; }

  // A pixel outside the picture is not drawn: shapes may run off its edge.
  void set(int x, int y, Rgb colour) {
    if (x < 0 || y < 0 || x >= width_ || y >= height_) {
      return;
    }
    const std::size_t at = offset(x, y);
    bytes_[at] = colour.red;
    bytes_[at + 1] = colour.green;
    bytes_[at + 2] = colour.blue;
  }
  [[nodiscard]] Rgb at(int x, int y) const {
    const std::size_t i = offset(x, y);
    return {bytes_[i], bytes_[i + 1], bytes_[i + 2]};
  }
  void fill(int x, int y, int width, int height, Rgb colour) {
    for (int row = y; row < y + height; ++row) {
      for (int column = x; column < x + width; ++column) {
        set(column, row, colour);
      }
    }
  }

 private:
  [[nodiscard]] std::size_t offset(int x, int y) const {
    return 3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x));
  }

  int width_;
  int height_;
  std::vector<std::uint8_t> bytes_;
};

}  // namespace stencil::board::sim
