// Surfaces of revolution about the tool axis, as implicit functions of (r, z), with their distance fields.
#pragma once

#include <cmath>
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

// Inline: these run for every point the BSP classifies, in the 1 kHz cycle.

namespace implicit_surface_detail {

inline constexpr double kInvSqrt2 = 0.70710678118654752;

// Below this distance from a centre the gradient direction is numerically meaningless.
inline constexpr double kDegenerateDistance_mm = 1e-12;

inline double side_sign(const ImplicitSurface& surface) {
  return surface.solid_side == SolidSide::Below ? 1.0 : -1.0;
}

// Offset of the point from the circle (or axis point) a sphere or torus is built around.
inline MeridianDirection offset_from_center(const ImplicitSurface& surface, MeridianPoint point) {
  const double center_r = surface.kind == SurfaceKind::Torus ? surface.center_r_mm : 0.0;
  return {point.r_mm - center_r, point.z_mm - surface.center_z_mm};
}

}  // namespace implicit_surface_detail

// The natural function f(r, z) of the surface, in mm (negative below/inside, zero on it).

[[nodiscard]] inline double surface_function(const ImplicitSurface& surface, MeridianPoint point) {
  switch (surface.kind) {
    case SurfaceKind::PlaneZ:
      return point.z_mm - surface.center_z_mm;
    case SurfaceKind::Cylinder:
      return point.r_mm - surface.radius_mm;
    case SurfaceKind::Sphere:
    case SurfaceKind::Torus: {
      // sqrt rather than hypot: millimetre values cannot overflow, and hypot costs several times more.
      const MeridianDirection offset = implicit_surface_detail::offset_from_center(surface, point);
      return std::sqrt(offset.radial * offset.radial + offset.axial * offset.axial) - surface.radius_mm;
    }
  }
  return std::nan("");  // unreachable for a checked tree; NaN makes every comparison fail safe
}

// Distance from the point to the surface, positive on the solid side: -f on a Below surface, f on
// an Above surface. Real-time safe.

[[nodiscard]] inline double interior_distance(const ImplicitSurface& surface, MeridianPoint point) {
  return -implicit_surface_detail::side_sign(surface) * surface_function(surface, point);
}

// The unit direction in which interior_distance falls fastest (the way a point inside the solid
// leaves it through this surface), i.e. minus the gradient of interior_distance. Where the gradient
// is undefined (on the axis of a cylinder, at the centre of a sphere or torus tube) a fixed,
// documented choice is returned: radially out for a cylinder, (r, z) = (1, -1)/sqrt(2) otherwise.
// Real-time safe.

[[nodiscard]] inline MeridianDirection escape_direction(const ImplicitSurface& surface, MeridianPoint point) {
  // Gradient of f, then oriented: escape = side_sign * grad f.
  const double sign = implicit_surface_detail::side_sign(surface);
  switch (surface.kind) {
    case SurfaceKind::PlaneZ:
      return {0.0, sign};
    case SurfaceKind::Cylinder:
      return {sign, 0.0};
    case SurfaceKind::Sphere:
    case SurfaceKind::Torus: {
      const MeridianDirection offset = implicit_surface_detail::offset_from_center(surface, point);
      const double length = std::sqrt(offset.radial * offset.radial + offset.axial * offset.axial);
      if (length < implicit_surface_detail::kDegenerateDistance_mm) {
        return {implicit_surface_detail::kInvSqrt2, -implicit_surface_detail::kInvSqrt2};
      }
      return {sign * offset.radial / length, sign * offset.axial / length};
    }
  }
  return {0.0, 0.0};
}

}  // namespace stencil::geometry
