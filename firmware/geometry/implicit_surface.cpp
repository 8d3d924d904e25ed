// Distance fields of the tool's surfaces of revolution.
#include "firmware/geometry/implicit_surface.hpp"

#include <cmath>

namespace stencil::geometry {
namespace {

constexpr double kInvSqrt2 = 0.70710678118654752;

// Below this distance from a centre the gradient direction is numerically meaningless.
constexpr double kDegenerateDistance_mm = 1e-12;

double side_sign(const ImplicitSurface& surface) {
  return surface.solid_side == SolidSide::Below ? 1.0 : -1.0;
}

// Offset of the point from the circle (or axis point) a sphere or torus is built around.
MeridianDirection offset_from_center(const ImplicitSurface& surface, MeridianPoint point) {
  const double center_r = surface.kind == SurfaceKind::Torus ? surface.center_r_mm : 0.0;
  return {point.r_mm - center_r, point.z_mm - surface.center_z_mm};
}

}  // namespace

double surface_function(const ImplicitSurface& surface, MeridianPoint point) {
  switch (surface.kind) {
    case SurfaceKind::PlaneZ:
      return point.z_mm - surface.center_z_mm;
    case SurfaceKind::Cylinder:
      return point.r_mm - surface.radius_mm;
    case SurfaceKind::Sphere:
    case SurfaceKind::Torus: {
      // sqrt rather than hypot: millimetre values cannot overflow, and hypot costs several times more.
      const MeridianDirection offset = offset_from_center(surface, point);
      return std::sqrt(offset.radial * offset.radial + offset.axial * offset.axial) - surface.radius_mm;
    }
  }
  return std::nan("");  // unreachable for a checked tree; NaN makes every comparison fail safe
}

double interior_distance(const ImplicitSurface& surface, MeridianPoint point) {
  return -side_sign(surface) * surface_function(surface, point);
}

MeridianDirection escape_direction(const ImplicitSurface& surface, MeridianPoint point) {
  // Gradient of f, then oriented: escape = side_sign * grad f.
  const double sign = side_sign(surface);
  switch (surface.kind) {
    case SurfaceKind::PlaneZ:
      return {0.0, sign};
    case SurfaceKind::Cylinder:
      return {sign, 0.0};
    case SurfaceKind::Sphere:
    case SurfaceKind::Torus: {
      const MeridianDirection offset = offset_from_center(surface, point);
      const double length = std::sqrt(offset.radial * offset.radial + offset.axial * offset.axial);
      if (length < kDegenerateDistance_mm) {
        return {kInvSqrt2, -kInvSqrt2};
      }
      return {sign * offset.radial / length, sign * offset.axial / length};
    }
  }
  return {0.0, 0.0};
}

}  // namespace stencil::geometry
