// The tool's surfaces of revolution as functions of (r, z) (geometry/implicit_surface.hpp): each
// kind's natural function is its signed distance, the solid side sets the interior distance's
// sign, the escape direction is the way that distance falls fastest (checked against a numerical
// gradient), and the fixed choices where the gradient is undefined.
#include <cmath>
#include <cstdint>

#include "firmware/core/geometry/implicit_surface.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::geometry;

namespace {

constexpr ImplicitSurface kPlane{SurfaceKind::PlaneZ, SolidSide::Below, 0.0, 2.0, 0.0};       // z = 2
constexpr ImplicitSurface kCylinder{SurfaceKind::Cylinder, SolidSide::Below, 0.0, 0.0, 1.5};   // r = 1.5
constexpr ImplicitSurface kSphere{SurfaceKind::Sphere, SolidSide::Below, 0.0, 1.5, 1.5};       // ball end
constexpr ImplicitSurface kTorus{SurfaceKind::Torus, SolidSide::Below, 2.0, 1.0, 1.0};         // bull-nose corner
constexpr ImplicitSurface kEdge{SurfaceKind::Torus, SolidSide::Above, 1.5, 12.0, 0.0};         // a concave edge

const double kInvSqrt2 = 1.0 / std::sqrt(2.0);

// Minus the gradient of interior_distance by central differences.
MeridianDirection falling_fastest(const ImplicitSurface& s, MeridianPoint p) {
  const double h = 1e-6;
  const double dr = interior_distance(s, {p.r_mm + h, p.z_mm}) - interior_distance(s, {p.r_mm - h, p.z_mm});
  const double dz = interior_distance(s, {p.r_mm, p.z_mm + h}) - interior_distance(s, {p.r_mm, p.z_mm - h});
  return {-dr / (2.0 * h), -dz / (2.0 * h)};
}

}  // namespace

TEST_GROUP(ImplicitSurface){};

TEST(ImplicitSurface, EachKindsFunctionIsItsSignedDistance) {
  DOUBLES_EQUAL(-0.5, surface_function(kPlane, {7.0, 1.5}), 1e-15);
  DOUBLES_EQUAL(0.5, surface_function(kCylinder, {2.0, 40.0}), 1e-15);
  DOUBLES_EQUAL(5.0 - 1.5, surface_function(kSphere, {3.0, 5.5}), 1e-15);  // (3, 4) from (0, 1.5)
  DOUBLES_EQUAL(-1.5, surface_function(kSphere, {0.0, 1.5}), 1e-15);      // the centre
  DOUBLES_EQUAL(5.0 - 1.0, surface_function(kTorus, {5.0, 5.0}), 1e-15);  // (3, 4) from (2, 1)
  DOUBLES_EQUAL(0.0, surface_function(kTorus, {2.0, 0.0}), 1e-15);        // the tube's bottom
  DOUBLES_EQUAL(0.5, surface_function(kEdge, {1.5, 12.5}), 1e-15);        // radius 0: the circle itself
}

TEST(ImplicitSurface, TheInteriorDistanceIsPositiveOnTheSolidSideOnly) {
  DOUBLES_EQUAL(0.5, interior_distance(kPlane, {1.0, 1.5}), 1e-15);
  DOUBLES_EQUAL(-0.5, interior_distance(kPlane, {1.0, 2.5}), 1e-15);
  ImplicitSurface over = kPlane;
  over.solid_side = SolidSide::Above;
  DOUBLES_EQUAL(-0.5, interior_distance(over, {1.0, 1.5}), 1e-15);
  DOUBLES_EQUAL(0.5, interior_distance(over, {1.0, 2.5}), 1e-15);
  DOUBLES_EQUAL(0.25, interior_distance(kCylinder, {1.25, 3.0}), 1e-15);
  DOUBLES_EQUAL(0.5, interior_distance(kEdge, {1.5, 12.5}), 1e-15);  // an edge has its solid all round it
}

TEST(ImplicitSurface, TheEscapeIsTheWayTheInteriorDistanceFallsFastest) {
  const ImplicitSurface surfaces[] = {kPlane, kCylinder, kSphere, kTorus, kEdge};
  const MeridianPoint points[] = {{0.3, 0.7}, {1.2, 1.9}, {2.5, 0.4}, {0.8, 3.0}, {1.6, 11.7}};
  for (const ImplicitSurface& s : surfaces) {
    for (const MeridianPoint p : points) {
      const MeridianDirection escape = escape_direction(s, p);
      const MeridianDirection expected = falling_fastest(s, p);
      DOUBLES_EQUAL(1.0, std::hypot(escape.radial, escape.axial), 1e-12);
      DOUBLES_EQUAL(expected.radial, escape.radial, 1e-6);
      DOUBLES_EQUAL(expected.axial, escape.axial, 1e-6);
    }
  }
}

TEST(ImplicitSurface, WhereTheGradientIsUndefinedTheEscapeIsTheDocumentedChoice) {
  // The centre of a sphere and of a torus's tube: out and down at 45 degrees.
  for (const ImplicitSurface& s : {kSphere, kTorus}) {
    const double centre_r = s.kind == SurfaceKind::Torus ? s.center_r_mm : 0.0;
    const MeridianDirection escape = escape_direction(s, {centre_r, s.center_z_mm});
    DOUBLES_EQUAL(kInvSqrt2, escape.radial, 1e-15);
    DOUBLES_EQUAL(-kInvSqrt2, escape.axial, 1e-15);
  }
  // A cylinder's axis: radially out, as anywhere inside it.
  const MeridianDirection on_axis = escape_direction(kCylinder, {0.0, 3.0});
  DOUBLES_EQUAL(1.0, on_axis.radial, 0.0);
  DOUBLES_EQUAL(0.0, on_axis.axial, 0.0);
}

TEST(ImplicitSurface, AKindNoTreeHoldsFailsSafe) {
  ImplicitSurface damaged = kSphere;
  damaged.kind = static_cast<SurfaceKind>(9);
  // NaN makes every comparison a tree walk makes false; no direction to escape in.
  CHECK(std::isnan(surface_function(damaged, {1.0, 1.0})));
  CHECK(std::isnan(interior_distance(damaged, {1.0, 1.0})));
  const MeridianDirection escape = escape_direction(damaged, {1.0, 1.0});
  DOUBLES_EQUAL(0.0, escape.radial, 0.0);
  DOUBLES_EQUAL(0.0, escape.axial, 0.0);
}
