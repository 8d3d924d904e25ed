// An independent reference for tool geometry: the tool's outline in the (r, z) half-plane as finite
// segments and arcs, with brute-force inside tests and exact distances. Shares no code with the BSP.
#pragma once

#include <vector>

#include "firmware/core/geometry/tool_spec.hpp"

namespace stencil::test {

struct ProfilePoint {
  double r;
  double z;
};

// The outline of the tool in the meridian half-plane, from the tip on the axis round to the top of
// the holder on the axis (the axis itself is not part of the surface).
class ToolProfileReference {
 public:
  explicit ToolProfileReference(const geometry::ToolSpec& spec);

  // Largest radius of the solid at height z, or a negative number where there is no material.
  double radius_at(double z) const;
  // Straightforward test from the outline's formula.
  bool contains(double r, double z) const;
  // Exact distance from (r, z) to the outline: the minimum over its finite pieces, endpoints included.
  double distance_to_surface(double r, double z) const;
  // A point on the surface, picked by two numbers in [0, 1): which piece (by length), and where on it.
  ProfilePoint surface_point(double piece_fraction, double along) const;

  double total_length() const { return flute_length_ + holder_length_; }
  double max_radius() const { return holder_radius_ > radius_ ? holder_radius_ : radius_; }

 private:
  struct Piece {
    bool is_arc;
    ProfilePoint from;    // segment start
    ProfilePoint to;      // segment end
    ProfilePoint center;  // arc centre
    double radius;        // arc radius
    double angle_from;    // arc start angle (radians, from +r towards +z)
    double angle_to;      // arc end angle
    double length;
  };
  void add_segment(ProfilePoint from, ProfilePoint to);
  void add_arc(ProfilePoint center, double radius, double angle_from, double angle_to);

  geometry::ToolSpec spec_;
  double radius_;
  double flute_length_;
  double holder_radius_;
  double holder_length_;
  std::vector<Piece> pieces_;
};

}  // namespace stencil::test
