// The tool's outline as segments and arcs, and brute-force distances to it.
#include "tests/support/tool_profile_reference.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace stencil::test {
namespace {

double distance(ProfilePoint a, ProfilePoint b) { return std::hypot(a.r - b.r, a.z - b.z); }

}  // namespace

ToolProfileReference::ToolProfileReference(const geometry::ToolSpec& spec)
    : spec_(spec),
      radius_(spec.diameter_mm / 2.0),
      flute_length_(spec.flute_length_mm),
      holder_radius_(spec.holder_diameter_mm / 2.0),
      holder_length_(spec.holder_length_mm) {
  const double half_pi = std::numbers::pi / 2.0;
  const double top = flute_length_ + holder_length_;
  switch (spec.kind) {
    case geometry::CutterKind::Flat:
      add_segment({0.0, 0.0}, {radius_, 0.0});
      add_segment({radius_, 0.0}, {radius_, flute_length_});
      break;
    case geometry::CutterKind::Ball:
      add_arc({0.0, radius_}, radius_, -half_pi, 0.0);
      add_segment({radius_, radius_}, {radius_, flute_length_});
      break;
    case geometry::CutterKind::BullNose: {
      const double corner = spec.corner_radius_mm;
      add_segment({0.0, 0.0}, {radius_ - corner, 0.0});
      add_arc({radius_ - corner, corner}, corner, -half_pi, 0.0);
      add_segment({radius_, corner}, {radius_, flute_length_});
      break;
    }
  }
  add_segment({radius_, flute_length_}, {holder_radius_, flute_length_});
  add_segment({holder_radius_, flute_length_}, {holder_radius_, top});
  add_segment({holder_radius_, top}, {0.0, top});
}

void ToolProfileReference::add_segment(ProfilePoint from, ProfilePoint to) {
  const double length = distance(from, to);
  if (length > 0.0) {
    pieces_.push_back({false, from, to, {0.0, 0.0}, 0.0, 0.0, 0.0, length});
  }
}

void ToolProfileReference::add_arc(ProfilePoint center, double radius, double angle_from, double angle_to) {
  const ProfilePoint from{center.r + radius * std::cos(angle_from), center.z + radius * std::sin(angle_from)};
  const ProfilePoint to{center.r + radius * std::cos(angle_to), center.z + radius * std::sin(angle_to)};
  pieces_.push_back({true, from, to, center, radius, angle_from, angle_to, radius * (angle_to - angle_from)});
}

double ToolProfileReference::radius_at(double z) const {
  if (z < 0.0 || z > flute_length_ + holder_length_) {
    return -1.0;
  }
  if (z > flute_length_) {
    return holder_radius_;
  }
  if (z == flute_length_) {
    return std::max(radius_, holder_radius_);
  }
  switch (spec_.kind) {
    case geometry::CutterKind::Flat:
      return radius_;
    case geometry::CutterKind::Ball:
      return z >= radius_ ? radius_ : std::sqrt(radius_ * radius_ - (radius_ - z) * (radius_ - z));
    case geometry::CutterKind::BullNose: {
      const double corner = spec_.corner_radius_mm;
      return z >= corner ? radius_ : (radius_ - corner) + std::sqrt(corner * corner - (corner - z) * (corner - z));
    }
  }
  return -1.0;
}

bool ToolProfileReference::contains(double r, double z) const { return r <= radius_at(z); }

double ToolProfileReference::distance_to_surface(double r, double z) const {
  const ProfilePoint p{r, z};
  double best = std::numeric_limits<double>::infinity();
  for (const Piece& piece : pieces_) {
    double d;
    if (piece.is_arc) {
      const double angle = std::atan2(z - piece.center.z, r - piece.center.r);
      if (angle >= piece.angle_from && angle <= piece.angle_to) {
        d = std::abs(distance(p, piece.center) - piece.radius);
      } else {
        d = std::min(distance(p, piece.from), distance(p, piece.to));
      }
    } else {
      const double dr = piece.to.r - piece.from.r;
      const double dz = piece.to.z - piece.from.z;
      const double t = std::clamp(((r - piece.from.r) * dr + (z - piece.from.z) * dz) / (dr * dr + dz * dz), 0.0, 1.0);
      d = distance(p, {piece.from.r + t * dr, piece.from.z + t * dz});
    }
    best = std::min(best, d);
  }
  return best;
}

ProfilePoint ToolProfileReference::surface_point(double piece_fraction, double along) const {
  double total = 0.0;
  for (const Piece& piece : pieces_) {
    total += piece.length;
  }
  double target = piece_fraction * total;
  for (const Piece& piece : pieces_) {
    if (target <= piece.length || &piece == &pieces_.back()) {
      if (piece.is_arc) {
        const double angle = piece.angle_from + along * (piece.angle_to - piece.angle_from);
        return {piece.center.r + piece.radius * std::cos(angle), piece.center.z + piece.radius * std::sin(angle)};
      }
      return {piece.from.r + along * (piece.to.r - piece.from.r), piece.from.z + along * (piece.to.z - piece.from.z)};
    }
    target -= piece.length;
  }
  return {0.0, 0.0};
}

}  // namespace stencil::test
