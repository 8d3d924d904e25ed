// The height field's mesh (a quad between each four cell centres, and the stock's four sides),
// projected orthographically, shaded and rasterized triangle by triangle into a depth buffer.
#include "board/sim/height_field_view.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Geometry>

namespace stencil::board::sim {
namespace {

// Seen from the front left (30 degrees round from looking along +y) and 35 degrees above.
constexpr double kAzimuthRad = 30.0 * 3.14159265358979323846 / 180.0;
constexpr double kElevationRad = 35.0 * 3.14159265358979323846 / 180.0;
constexpr Rgb kSideColour{150, 150, 150};

// The view: screen x right, screen y down (pixels), depth growing away from the eye.
class View {
 public:
  View(const PanelRect& panel, const HeightField& field) {
    const double width = field.columns * field.cell_mm, depth = field.rows * field.cell_mm;
    double top = field.floor_mm;
    for (const double h : field.heights) {
      top = std::max(top, h);
    }
    // Fit the stock's bounding box into the panel, centred.
    Eigen::Vector2d low = Eigen::Vector2d::Constant(HUGE_VAL), high = Eigen::Vector2d::Constant(-HUGE_VAL);
    for (const double x : {0.0, width}) {
      for (const double y : {0.0, depth}) {
        for (const double z : {field.floor_mm, top}) {
          const Eigen::Vector3d p = unscaled({x, y, z});
          low = low.cwiseMin(p.head<2>());
          high = high.cwiseMax(p.head<2>());
        }
      }
    }
    const Eigen::Vector2d span = (high - low).cwiseMax(1e-9);
    scale_ = 0.96 * std::min(panel.width / span.x(), panel.height / span.y());
    offset_ = Eigen::Vector2d(panel.x + 0.5 * panel.width, panel.y + 0.5 * panel.height) - scale_ * 0.5 * (low + high);
  }

  // World (mm, the field's own x and y) to screen pixels and depth (mm).
  [[nodiscard]] Eigen::Vector3d project(const Eigen::Vector3d& world) const {
    const Eigen::Vector3d p = unscaled(world);
    return {offset_.x() + scale_ * p.x(), offset_.y() + scale_ * p.y(), p.z()};
  }

 private:
  // Screen x, screen y (down) and depth in mm, before fitting.
  [[nodiscard]] static Eigen::Vector3d unscaled(const Eigen::Vector3d& w) {
    const double across = w.x() * std::cos(kAzimuthRad) - w.y() * std::sin(kAzimuthRad);
    const double away = w.x() * std::sin(kAzimuthRad) + w.y() * std::cos(kAzimuthRad);
    const double up = away * std::sin(kElevationRad) + w.z() * std::cos(kElevationRad);
    return {across, -up, away * std::cos(kElevationRad) - w.z() * std::sin(kElevationRad)};
  }

  double scale_ = 1.0;
  Eigen::Vector2d offset_ = Eigen::Vector2d::Zero();
};

class Rasterizer {
 public:
  Rasterizer(RgbImage& image, const PanelRect& panel, const View& view)
      : image_(image),
        panel_(panel),
        view_(view),
        depth_(static_cast<std::size_t>(panel.width) * static_cast<std::size_t>(panel.height),
               std::numeric_limits<double>::infinity()) {}

  // A world triangle in `colour`, lit by how squarely it faces the light (either side of it).
  void triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, Rgb colour) {
    const Eigen::Vector3d normal = (b - a).cross(c - a);
    if (normal.squaredNorm() == 0.0) {
      return;
    }
    static const Eigen::Vector3d light = Eigen::Vector3d(-0.5, -0.7, 1.0).normalized();
    const double lit = 0.35 + 0.65 * std::abs(normal.normalized().dot(light));
    const auto shade = [lit](std::uint8_t channel) { return static_cast<std::uint8_t>(std::lround(channel * lit)); };
    fill(view_.project(a), view_.project(b), view_.project(c), {shade(colour.red), shade(colour.green), shade(colour.blue)});
  }

 private:
  // Every pixel whose centre is in the screen triangle (p, q, r) and nearer than what is there.
  void fill(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& r, Rgb colour) {
    const double area = (q.x() - p.x()) * (r.y() - p.y()) - (r.x() - p.x()) * (q.y() - p.y());
    if (std::abs(area) < 1e-12) {
      return;  // edge-on
    }
    const int x0 = std::max(panel_.x, static_cast<int>(std::floor(std::min({p.x(), q.x(), r.x()}))));
    const int x1 = std::min(panel_.x + panel_.width - 1, static_cast<int>(std::ceil(std::max({p.x(), q.x(), r.x()}))));
    const int y0 = std::max(panel_.y, static_cast<int>(std::floor(std::min({p.y(), q.y(), r.y()}))));
    const int y1 = std::min(panel_.y + panel_.height - 1, static_cast<int>(std::ceil(std::max({p.y(), q.y(), r.y()}))));
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        const double sx = x + 0.5, sy = y + 0.5;
        const double w0 = ((q.x() - sx) * (r.y() - sy) - (r.x() - sx) * (q.y() - sy)) / area;
        const double w1 = ((r.x() - sx) * (p.y() - sy) - (p.x() - sx) * (r.y() - sy)) / area;
        const double w2 = 1.0 - w0 - w1;
        if (w0 < 0.0 || w1 < 0.0 || w2 < 0.0) {
          continue;
        }
        const double depth = w0 * p.z() + w1 * q.z() + w2 * r.z();
        double& nearest = depth_[static_cast<std::size_t>(y - panel_.y) * static_cast<std::size_t>(panel_.width) +
                                 static_cast<std::size_t>(x - panel_.x)];
        if (depth < nearest) {
          nearest = depth;
          image_.set(x, y, colour);
        }
      }
    }
  }

  RgbImage& image_;
  PanelRect panel_;
  const View& view_;
  std::vector<double> depth_;
};

}  // namespace

void draw_height_field(RgbImage& image, const PanelRect& panel, const HeightField& field) {
  if (field.columns <= 0 || field.rows <= 0 || panel.width <= 0 || panel.height <= 0) {
    return;
  }
  const View view(panel, field);
  Rasterizer rasterizer(image, panel, view);
  const auto index = [&](int column, int row) {
    return static_cast<std::size_t>(row) * static_cast<std::size_t>(field.columns) + static_cast<std::size_t>(column);
  };
  // Each cell's top is its centre at its height; the outer cells reach out to the stock's edge.
  const auto top = [&](int column, int row) {
    const double x = std::clamp(column + 0.5, 0.0, static_cast<double>(field.columns)) * field.cell_mm;
    const double y = std::clamp(row + 0.5, 0.0, static_cast<double>(field.rows)) * field.cell_mm;
    return Eigen::Vector3d(x, y, field.heights[index(std::clamp(column, 0, field.columns - 1),
                                                     std::clamp(row, 0, field.rows - 1))]);
  };
  // The quad between four cell tops (from one past each edge, so that the stock's edge is drawn),
  // in the colour of the highest: where the quad is a wall, the wall is that cell's side.
  const auto colour_of = [&](int column, int row) {
    return field.colours[index(std::clamp(column, 0, field.columns - 1), std::clamp(row, 0, field.rows - 1))];
  };
  for (int row = -1; row < field.rows; ++row) {
    for (int column = -1; column < field.columns; ++column) {
      const Eigen::Vector3d a = top(column, row), b = top(column + 1, row), c = top(column + 1, row + 1),
                            d = top(column, row + 1);
      const double highest = std::max({a.z(), b.z(), c.z(), d.z()});
      const Rgb colour = highest == a.z()   ? colour_of(column, row)
                         : highest == b.z() ? colour_of(column + 1, row)
                         : highest == c.z() ? colour_of(column + 1, row + 1)
                                            : colour_of(column, row + 1);
      rasterizer.triangle(a, b, c, colour);
      rasterizer.triangle(a, c, d, colour);
    }
  }
  // The four sides, from the edge's tops down to the floor.
  const auto side = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    const Eigen::Vector3d a_floor(a.x(), a.y(), field.floor_mm), b_floor(b.x(), b.y(), field.floor_mm);
    rasterizer.triangle(a, b, b_floor, kSideColour);
    rasterizer.triangle(a, b_floor, a_floor, kSideColour);
  };
  for (int column = -1; column < field.columns; ++column) {
    side(top(column, -1), top(column + 1, -1));
    side(top(column, field.rows), top(column + 1, field.rows));
  }
  for (int row = -1; row < field.rows; ++row) {
    side(top(-1, row), top(-1, row + 1));
    side(top(field.columns, row), top(field.columns, row + 1));
  }
}

}  // namespace stencil::board::sim
