// The picture of the machined stock beside the report, as a CAM verification shows it: a top view
// coloured by each cell's signed distance from the part and what this tool could still remove there,
// with a legend in mm, and beside it a shaded 3-D view of the stock in the same colours. PNG, the
// same bytes for the same result.
#pragma once

#include <string>

#include "board/sim/sim_job.hpp"

namespace stencil::board::sim {

inline constexpr int kPictureWidthPx = 1600;
inline constexpr int kPictureHeightPx = 720;

// The colours' bounds, mm: of signed distance (SimResult::signed_distance_mm), then of the stock
// this tool could still remove (SimResult::unmachined_heights).
inline constexpr double kGougeToleranceMm = 0.005;  // deeper into the part than this: red (the gouge bar)
inline constexpr double kOnPartMm = 0.05;           // within this of the part: green
inline constexpr double kLeftThicknessMm = 0.05;    // farther, and this much or more left to cut: blue
inline constexpr double kLeftFullMm = 2.0;          // the blue's deepest, for this much left or more

// A pixel of the picture, from its top left.
struct PixelPosition {
  int x, y;
};

// Where the top view draws the centre of cell (column, row) of a `columns` x `rows` stock (rows run
// up the picture as y runs up the world).
[[nodiscard]] PixelPosition top_view_pixel(int columns, int rows, int column, int row);

// Writes the picture of `result`'s stock: each cell red where the stock was cut into the part,
// green on the part, blue (deeper for more, full at kLeftFullMm) where this tool could still remove
// stock, and grey where there is less than the tolerance it could remove (the floor, cusps, stock
// out of its reach). False with `error` naming the path on failure.
[[nodiscard]] bool write_picture_png(const std::string& path, const SimResult& result, std::string& error);

}  // namespace stencil::board::sim
