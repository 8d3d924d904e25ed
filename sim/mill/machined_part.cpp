// Ground truth of the cut: legs of the mill's path into the Z-map, gouge against the triangles.
#include "sim/mill/machined_part.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>

#include "sim/mill/surface_distance.hpp"
#include "sim/mill/triangle_distance.hpp"

namespace stencil::sim {
namespace {

// The tool's footprint as offsets in cells, with the cutter's height over each.
struct Offset {
  int dc, dr;
  double lift;
};

std::vector<Offset> footprint_of(const StockZmap& grid, const ToolProfile& tool) {
  const double cell = grid.cell_mm();
  const int reach = static_cast<int>(std::ceil(tool.radius_mm / cell));
  std::vector<Offset> footprint;
  for (int dr = -reach; dr <= reach; ++dr) {
    for (int dc = -reach; dc <= reach; ++dc) {
      const double lift = tool.height_at(cell * std::sqrt(static_cast<double>(dr * dr + dc * dc)));
      if (std::isfinite(lift)) {
        footprint.push_back({dc, dr, lift});
      }
    }
  }
  return footprint;
}

Eigen::Vector3d vertex(const tables::PackedTriangle& triangle, int i) {
  const tables::PackedPoint& v = triangle.vertices[static_cast<std::size_t>(i)];
  return {v.x_mm, v.y_mm, v.z_mm};
}

// Distance between two triangles: they are apart by the nearest of one's edges to the other (and
// touch when an edge crosses the other, which the segment distance reports as 0).
double triangle_triangle_distance(const std::array<Eigen::Vector3d, 3>& p, const std::array<Eigen::Vector3d, 3>& q) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < 3; ++i) {
    best = std::min(best, segment_triangle_distance(p[i], p[(i + 1) % 3], q[0], q[1], q[2]));
    best = std::min(best, segment_triangle_distance(q[i], q[(i + 1) % 3], p[0], p[1], p[2]));
  }
  return best;
}

}  // namespace

std::vector<double> lowest_tips(const StockZmap& grid, const std::vector<double>& part_heights,
                                const ToolProfile& tool) {
  const int columns = grid.columns(), rows = grid.rows();
  const double floor = grid.box().low_mm.z();
  const std::vector<Offset> footprint = footprint_of(grid, tool);
  std::vector<double> tip(part_heights.size(), floor);
  // A row of cells at a time, each of the footprint's offsets over the whole row: every cell still
  // takes the maximum over the footprint in the footprint's order (the same result, bit for bit),
  // but the innermost loop runs along a row and vectorises, with no bounds test per offset.
  for (int row = 0; row < rows; ++row) {
    double* const out = tip.data() + static_cast<std::ptrdiff_t>(row) * columns;
    for (const Offset& o : footprint) {
      const int r = row + o.dr;
      if (r < 0 || r >= rows) {
        continue;
      }
      const double* const in = part_heights.data() + static_cast<std::ptrdiff_t>(r) * columns;
      const double lift = o.lift;
      for (int column = std::max(0, -o.dc), end = std::min(columns, columns - o.dc); column < end; ++column) {
        out[column] = std::max(out[column], in[column + o.dc] - lift);
      }
    }
  }
  return tip;
}

MachinedPart::MachinedPart(const tables::PartTables& part, const StockBox& stock, const motion::MachineFrames& frames,
                           std::function<double()> now_s)
    : part_(part),
      frames_(frames),
      now_s_(std::move(now_s)),
      stock_(stock, 0.05),
      tool_(ToolProfile::of(part.tool.spec)),
      gouge_measured_(part.tool.spec.kind == geometry::CutterKind::Ball) {}

Eigen::Vector3d MachinedPart::world_of(const std::array<std::int64_t, kMillAxisCount>& axis_steps) const {
  motion::MachineSteps steps{};
  for (std::size_t i = 0; i < 3; ++i) {
    steps.axis[i] = static_cast<std::int32_t>(axis_steps[i] - home_[i]);
  }
  return motion::steps_to_world(frames_, steps);
}

void MachinedPart::arm(const std::array<std::int64_t, kMillAxisCount>& home_axis_steps) {
  home_ = home_axis_steps;
  armed_ = true;
  leg_axis_ = -1;
  leg_start_ = leg_end_ = world_of(home_axis_steps);
  corner(leg_start_);
}

void MachinedPart::corner(const Eigen::Vector3d& tip) {
  last_corner_ = {now_s_ ? now_s_() : 0.0, tip};
  if (trace_ != nullptr) {
    std::fprintf(trace_, "%.6f,%.6f,%.6f,%.6f\n", last_corner_.t_s, tip.x(), tip.y(), tip.z());
  }
}

void MachinedPart::axis_moved(Axis axis, const std::array<std::int64_t, kMillAxisCount>& axis_steps) {
  if (!armed_) {
    return;
  }
  const int moving = static_cast<int>(axis);
  if (leg_axis_ >= 0 && moving != leg_axis_) {
    finish_leg();
  }
  leg_axis_ = moving;
  leg_end_ = world_of(axis_steps);
}

void MachinedPart::flush() {
  if (armed_ && leg_axis_ >= 0) {
    finish_leg();
  }
}

void MachinedPart::cut_recorded_leg(const Eigen::Vector3d& from_mm, const Eigen::Vector3d& to_mm) {
  stock_.cut(from_mm, to_mm, tool_);
  if (gouge_measured_) {
    max_gouge_mm_ = std::max(max_gouge_mm_, leg_gouge(from_mm, to_mm));
  }
  ++legs_;
}

void MachinedPart::finish_leg() {
  stock_.cut(leg_start_, leg_end_, tool_);
  if (gouge_measured_) {
    max_gouge_mm_ = std::max(max_gouge_mm_, leg_gouge(leg_start_, leg_end_));
  }
  ++legs_;
  corner(leg_end_);
  leg_start_ = leg_end_;
  leg_axis_ = -1;
}

// The ball end mill's cutter is a capsule of radius R round the axis from tip + R up to the top of
// the flutes. Moved along one axis, it sweeps that capsule's core (a segment) into a vertical
// rectangle (a horizontal move) or a longer segment (a vertical one), grown by R: a triangle of the
// part is cut into by R less its distance from that core.
double tool_depth_along(const tables::PartTables& part, const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
  const double radius = part.tool.envelope.cutter_radius_mm;
  const double flutes = part.tool.envelope.flute_length_mm;
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d low_from = from + radius * up, low_to = to + radius * up;
  const Eigen::Vector3d high_from = from + flutes * up, high_to = to + flutes * up;
  const bool vertical = from.x() == to.x() && from.y() == to.y();
  const Eigen::Vector3d core_low = vertical ? (from.z() < to.z() ? low_from : low_to) : low_from;
  const Eigen::Vector3d core_high = vertical ? (from.z() < to.z() ? high_to : high_from) : high_to;
  const Eigen::Vector3d box_low = low_from.cwiseMin(low_to).array() - radius;
  const Eigen::Vector3d box_high = high_from.cwiseMax(high_to).array() + radius;
  double deepest = 0.0;
  for (std::uint32_t t = 0; t < part.triangle_count(); ++t) {
    const std::array<Eigen::Vector3d, 3> triangle{vertex(part.triangles[t], 0), vertex(part.triangles[t], 1),
                                                  vertex(part.triangles[t], 2)};
    const Eigen::Vector3d t_low = triangle[0].cwiseMin(triangle[1]).cwiseMin(triangle[2]);
    const Eigen::Vector3d t_high = triangle[0].cwiseMax(triangle[1]).cwiseMax(triangle[2]);
    if ((t_low.array() > box_high.array()).any() || (t_high.array() < box_low.array()).any()) {
      continue;  // farther than the radius from the swept core
    }
    double distance = 0.0;
    if (vertical || from == to) {
      distance = segment_triangle_distance(core_low, core_high, triangle[0], triangle[1], triangle[2]);
    } else {
      const std::array<Eigen::Vector3d, 3> half_a{low_from, low_to, high_to};
      const std::array<Eigen::Vector3d, 3> half_b{low_from, high_to, high_from};
      distance = std::min(triangle_triangle_distance(half_a, triangle), triangle_triangle_distance(half_b, triangle));
    }
    deepest = std::max(deepest, radius - distance);
  }
  return deepest;
}

double MachinedPart::leg_gouge(const Eigen::Vector3d& from, const Eigen::Vector3d& to) const {
  return tool_depth_along(part_, from, to);
}

std::vector<double> part_top_heights(const tables::PartTables& part, const StockZmap& grid) {
  // The part's top over each cell centre: the highest triangle above it (the part stands on the
  // floor; a cell with no part over it is the floor's height).
  std::vector<double> heights(static_cast<std::size_t>(grid.columns()) * static_cast<std::size_t>(grid.rows()),
                              grid.box().low_mm.z());
  const double cell = grid.cell_mm();
  const Eigen::Vector3d origin = grid.box().low_mm;
  for (std::uint32_t t = 0; t < part.triangle_count(); ++t) {
    const Eigen::Vector3d a = vertex(part.triangles[t], 0), b = vertex(part.triangles[t], 1),
                          c = vertex(part.triangles[t], 2);
    const double area = (b.x() - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (b.y() - a.y());
    if (std::abs(area) < 1e-12) {
      continue;  // seen edge-on from above: a wall
    }
    const int c0 = std::max(0, static_cast<int>(std::floor((std::min({a.x(), b.x(), c.x()}) - origin.x()) / cell)));
    const int c1 = std::min(grid.columns() - 1, static_cast<int>(std::floor((std::max({a.x(), b.x(), c.x()}) - origin.x()) / cell)));
    const int r0 = std::max(0, static_cast<int>(std::floor((std::min({a.y(), b.y(), c.y()}) - origin.y()) / cell)));
    const int r1 = std::min(grid.rows() - 1, static_cast<int>(std::floor((std::max({a.y(), b.y(), c.y()}) - origin.y()) / cell)));
    for (int row = r0; row <= r1; ++row) {
      for (int column = c0; column <= c1; ++column) {
        const Eigen::Vector2d p = grid.centre(column, row);
        const double w0 = ((b.x() - p.x()) * (c.y() - p.y()) - (c.x() - p.x()) * (b.y() - p.y())) / area;
        const double w1 = ((c.x() - p.x()) * (a.y() - p.y()) - (a.x() - p.x()) * (c.y() - p.y())) / area;
        const double w2 = 1.0 - w0 - w1;
        if (w0 < 0.0 || w1 < 0.0 || w2 < 0.0) {
          continue;
        }
        double& height = heights[static_cast<std::size_t>(row) * static_cast<std::size_t>(grid.columns()) +
                                 static_cast<std::size_t>(column)];
        height = std::max(height, w0 * a.z() + w1 * b.z() + w2 * c.z());
      }
    }
  }
  return heights;
}

std::vector<double> MachinedPart::part_heights() const { return part_top_heights(part_, stock_); }

std::vector<float> MachinedPart::signed_distances(const std::vector<double>& part_heights, double reach_mm) const {
  std::vector<double> heights;
  heights.reserve(part_heights.size());
  for (int row = 0; row < stock_.rows(); ++row) {
    for (int column = 0; column < stock_.columns(); ++column) {
      heights.push_back(stock_.height(column, row));
    }
  }
  const SurfaceDistance surface(triangles_of(part_), reach_mm);
  const CellGrid grid{stock_.columns(), stock_.rows(), stock_.cell_mm(), stock_.box().low_mm.head<2>()};
  return sim::signed_distances(surface, grid, heights, part_heights);
}

std::vector<double> MachinedPart::reachable_heights(const std::vector<double>& part, double allowance_mm) const {
  const int columns = stock_.columns(), rows = stock_.rows();
  const double top = stock_.box().high_mm.z();
  // The lowest tips of the tool grown by the allowance (its tip that much lower than the real one's).
  ToolProfile grown = tool_;
  grown.radius_mm += allowance_mm;
  grown.corner_radius_mm += grown.kind == geometry::CutterKind::BullNose ? allowance_mm : 0.0;
  std::vector<double> tip = lowest_tips(stock_, part, grown);
  for (double& t : tip) {
    t += allowance_mm;
  }
  // The lowest the tool's surface can come over each cell from any of those tips.
  const std::vector<Offset> footprint = footprint_of(stock_, tool_);
  std::vector<double> reachable(part.size(), top);
  // As in lowest_tips: a row at a time, the footprint's offsets in order, along the row.
  for (int row = 0; row < rows; ++row) {
    double* const out = reachable.data() + static_cast<std::ptrdiff_t>(row) * columns;
    for (const Offset& o : footprint) {
      const int r = row + o.dr;
      if (r < 0 || r >= rows) {
        continue;
      }
      const double* const in = tip.data() + static_cast<std::ptrdiff_t>(r) * columns;
      const double lift = o.lift;
      for (int column = std::max(0, -o.dc), end = std::min(columns, columns - o.dc); column < end; ++column) {
        out[column] = std::min(out[column], in[column + o.dc] + lift);
      }
    }
    const double* const floor_of = part.data() + static_cast<std::ptrdiff_t>(row) * columns;
    for (int column = 0; column < columns; ++column) {
      out[column] = std::max(out[column], floor_of[column]);
    }
  }
  return reachable;
}

MachinedPart::Volumes MachinedPart::volumes() const {
  const std::vector<double> part = part_heights();
  const std::vector<double> reachable = reachable_heights(part, allowance_mm_);
  const std::vector<double> exact = allowance_mm_ > 0.0 ? reachable_heights(part, 0.0) : reachable;
  const double cell = stock_.cell_mm();
  const double floor = stock_.box().low_mm.z();
  const double top = stock_.box().high_mm.z();
  Volumes v{stock_.removed_volume_mm3(), 0.0, 0.0, 0.0, 0.0, std::vector<double>(reachable.size(), 0.0)};
  for (int row = 0; row < stock_.rows(); ++row) {
    for (int column = 0; column < stock_.columns(); ++column) {
      const std::size_t i = static_cast<std::size_t>(row) * static_cast<std::size_t>(stock_.columns()) + static_cast<std::size_t>(column);
      const double left = stock_.height(column, row);
      if (reachable[i] < top) {
        v.unmachined_per_cell_mm[i] = std::max(0.0, left - std::max(reachable[i], floor));
      }
      v.reachable_mm3 += std::max(0.0, top - reachable[i]);
      v.unmachined_mm3 += v.unmachined_per_cell_mm[i];
      v.gouge_mm3 += std::max(0.0, part[i] - left);
      v.allowance_mm3 += std::max(0.0, std::max(reachable[i], floor) - std::max(exact[i], floor));
    }
  }
  v.allowance_mm3 *= cell * cell;
  v.reachable_mm3 *= cell * cell;
  v.unmachined_mm3 *= cell * cell;
  v.gouge_mm3 *= cell * cell;
  return v;
}

}  // namespace stencil::sim
