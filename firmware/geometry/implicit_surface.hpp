// Surfaces of revolution about the tool axis, as implicit functions of (r, z), with their distance fields.
#pragma once

#include <cstdint>

namespace stencil::geometry {

// A point in the tool's meridian half-plane: r = sqrt(x^2 + y^2) >= 0 and z along the tool axis
// from the tip (mm).
struct MeridianPoint {
  double r_mm;
  double z_mm;
};

// A unit direction in the meridian half-plane: the radial and axial components.
struct MeridianDirection {
  double radial;
  double axial;
};

enum class SurfaceKind : std::uint8_t {
  PlaneZ,    // z = center_z_mm
  Cylinder,  // r = radius_mm
  Sphere,    // |(r, z) - (0, center_z_mm)| = radius_mm
  Torus,     // |(r, z) - (center_r_mm, center_z_mm)| = radius_mm; radius 0 is a circular edge
};

// Which side of the surface the tool's material is on, for surfaces that bound the solid.
enum class SolidSide : std::int8_t {
  Below = 1,   // where the natural function f is negative (inside a cylinder, sphere, torus tube; under a plane)
  Above = -1,  // where f is positive (over a plane; around a concave circular edge)
};

// One implicit surface. Its natural function f(r, z) is an exact signed Euclidean distance:
// PlaneZ z - c, Cylinder r - R, Sphere |(r, z) - (0, c)| - R, Torus |(r, z) - (a, c)| - R.
// Plain data: tool trees store it as-is.
struct ImplicitSurface {
  SurfaceKind kind;
  SolidSide solid_side;
  double center_r_mm;  // Torus only: radius of the circle the tube's centre runs along
  double center_z_mm;  // PlaneZ, Sphere, Torus
  double radius_mm;    // Cylinder, Sphere, Torus
};

// The natural function f(r, z) of the surface, in mm (negative below/inside, zero on it).
[[nodiscard]] double surface_function(const ImplicitSurface& surface, MeridianPoint point);

// Distance from the point to the surface, positive on the solid side: -f on a Below surface, f on
// an Above surface. Real-time safe.
[[nodiscard]] double interior_distance(const ImplicitSurface& surface, MeridianPoint point);

// The unit direction in which interior_distance falls fastest (the way a point inside the solid
// leaves it through this surface), i.e. minus the gradient of interior_distance. Where the gradient
// is undefined (on the axis of a cylinder, at the centre of a sphere or torus tube) a fixed,
// documented choice is returned: radially out for a cylinder, (r, z) = (1, -1)/sqrt(2) otherwise.
// Real-time safe.
[[nodiscard]] MeridianDirection escape_direction(const ImplicitSurface& surface, MeridianPoint point);

}  // namespace stencil::geometry
