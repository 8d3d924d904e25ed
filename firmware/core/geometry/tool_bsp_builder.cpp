// Builds the tool's BSP: partitions into cutter and holder, boundary tests, then the bisectors
// between candidate faces, so every interior region is the set of points nearest one face.
//
// Why these regions are exact (R cutter radius, L flute length, Rh >= R holder radius, Lh >= R
// holder length, L >= R): below z = L the nearest face is always one of the cutter's own (bottom,
// ball or corner, side), because any other face is at least R - r away; above z = L it is the
// holder's side or top, or where the holder is wider, the downward step (r >= R) or the concave edge
// at (R, L) (r < R). Within each such set, the nearest of the candidates' exact distances is the
// distance to the solid, so a tournament of bisectors picks the region.
#include "firmware/core/geometry/tool_bsp_builder.hpp"

#include <cmath>
#include <cstdint>

namespace stencil::geometry {
namespace {

class TreeWriter {
 public:
  explicit TreeWriter(ToolBsp& tool) : tool_(tool) {}

  std::uint8_t surface(SurfaceKind kind, SolidSide side, double center_r_mm, double center_z_mm, double radius_mm) {
    const std::uint8_t index = tool_.surface_count++;
    tool_.surfaces[index] = {kind, side, center_r_mm, center_z_mm, radius_mm};
    return index;
  }

  std::uint8_t region(std::uint8_t surface_index, ToolFace face) {
    const std::uint8_t index = tool_.region_count++;
    tool_.regions[index] = {surface_index, face};
    return index;
  }

  // Nodes are reserved before their children are built, so every link points forward.
  std::uint8_t reserve_node() { return tool_.node_count++; }

  BspLink set_node(std::uint8_t index, NodeTest test, std::uint8_t surface_a, std::uint8_t surface_b,
                   BspLink when_true, BspLink when_false) {
    tool_.nodes[index] = {test, surface_a, surface_b, when_true, when_false};
    return {BspLink::Kind::Node, index};
  }

  std::uint8_t surface_of(std::uint8_t region_index) const { return tool_.regions[region_index].surface; }

 private:
  ToolBsp& tool_;
};

constexpr BspLink kOutside{BspLink::Kind::Outside, 0};

BspLink region_link(std::uint8_t region) { return {BspLink::Kind::Region, region}; }

// Inside boundary `surface`, continue with build_inside(); otherwise outside.
template <typename BuildInside>
BspLink inside_boundary(TreeWriter& writer, std::uint8_t surface, BuildInside build_inside) {
  const std::uint8_t node = writer.reserve_node();
  const BspLink inside = build_inside();
  return writer.set_node(node, NodeTest::InsideBoundary, surface, 0, inside, kOutside);
}

template <typename BuildBelow, typename BuildAbove>
BspLink partition(TreeWriter& writer, std::uint8_t surface, BuildBelow build_below, BuildAbove build_above) {
  const std::uint8_t node = writer.reserve_node();
  const BspLink below = build_below();
  const BspLink above = build_above();
  return writer.set_node(node, NodeTest::BelowPartition, surface, 0, below, above);
}

BspLink nearer_of_two(TreeWriter& writer, std::uint8_t region_a, std::uint8_t region_b) {
  const std::uint8_t node = writer.reserve_node();
  return writer.set_node(node, NodeTest::NearerThan, writer.surface_of(region_a), writer.surface_of(region_b),
                         region_link(region_a), region_link(region_b));
}

BspLink nearest_of_three(TreeWriter& writer, std::uint8_t region_a, std::uint8_t region_b, std::uint8_t region_c) {
  const std::uint8_t node = writer.reserve_node();
  const BspLink a_or_c = nearer_of_two(writer, region_a, region_c);
  const BspLink b_or_c = nearer_of_two(writer, region_b, region_c);
  return writer.set_node(node, NodeTest::NearerThan, writer.surface_of(region_a), writer.surface_of(region_b),
                         a_or_c, b_or_c);
}

ToolBuildResult ok() { return {true, nullptr, nullptr, 0.0}; }

ToolBuildResult error(const char* field, const char* expected, double value) {
  return {false, field, expected, value};
}

bool finite_in_range(double value, double low_exclusive) {
  return std::isfinite(value) && value > low_exclusive && value <= kMaxToolDimension_mm;
}

ToolBuildResult check_spec(const ToolSpec& spec) {
  if (spec.kind != CutterKind::Flat && spec.kind != CutterKind::Ball && spec.kind != CutterKind::BullNose) {
    return error("kind", "flat, ball or bull-nose", static_cast<double>(spec.kind));
  }
  if (!finite_in_range(spec.diameter_mm, 0.0)) {
    return error("diameter_mm", "a finite number greater than 0 and at most 1000", spec.diameter_mm);
  }
  const double radius = spec.diameter_mm / 2.0;
  if (!std::isfinite(spec.flute_length_mm) || spec.flute_length_mm < radius ||
      spec.flute_length_mm > kMaxToolDimension_mm) {
    return error("flute_length_mm", "a finite number at least the cutter radius and at most 1000",
                 spec.flute_length_mm);
  }
  if (spec.kind == CutterKind::BullNose &&
      (!std::isfinite(spec.corner_radius_mm) || spec.corner_radius_mm <= 0.0 || spec.corner_radius_mm > radius)) {
    return error("corner_radius_mm", "a finite number greater than 0 and at most the cutter radius",
                 spec.corner_radius_mm);
  }
  if (!std::isfinite(spec.holder_diameter_mm) || spec.holder_diameter_mm < spec.diameter_mm ||
      spec.holder_diameter_mm > kMaxToolDimension_mm) {
    return error("holder_diameter_mm", "a finite number at least the cutter diameter and at most 1000",
                 spec.holder_diameter_mm);
  }
  if (!std::isfinite(spec.holder_length_mm) || spec.holder_length_mm < radius ||
      spec.holder_length_mm > kMaxToolDimension_mm) {
    return error("holder_length_mm", "a finite number at least the cutter radius and at most 1000",
                 spec.holder_length_mm);
  }
  return ok();
}

// The part below z = L: bottom, ball or corner, and side, by cutter kind.
BspLink build_cutter(TreeWriter& writer, const ToolSpec& spec, std::uint8_t side_surface, std::uint8_t side_region) {
  const double radius = spec.diameter_mm / 2.0;
  switch (spec.kind) {
    case CutterKind::Flat: {
      const std::uint8_t bottom = writer.surface(SurfaceKind::PlaneZ, SolidSide::Above, 0.0, 0.0, 0.0);
      const std::uint8_t bottom_region = writer.region(bottom, ToolFace::Bottom);
      return inside_boundary(writer, bottom, [&] {
        return inside_boundary(writer, side_surface, [&] { return nearer_of_two(writer, bottom_region, side_region); });
      });
    }
    case CutterKind::Ball: {
      const std::uint8_t ball = writer.surface(SurfaceKind::Sphere, SolidSide::Below, 0.0, radius, radius);
      const std::uint8_t ball_region = writer.region(ball, ToolFace::BallEnd);
      const std::uint8_t equator = writer.surface(SurfaceKind::PlaneZ, SolidSide::Below, 0.0, radius, 0.0);
      return partition(
          writer, equator, [&] { return inside_boundary(writer, ball, [&] { return region_link(ball_region); }); },
          [&] { return inside_boundary(writer, side_surface, [&] { return region_link(side_region); }); });
    }
    case CutterKind::BullNose: {
      const double corner = spec.corner_radius_mm;
      const double flat_radius = radius - corner;
      const std::uint8_t bottom = writer.surface(SurfaceKind::PlaneZ, SolidSide::Above, 0.0, 0.0, 0.0);
      const std::uint8_t bottom_region = writer.region(bottom, ToolFace::Bottom);
      const std::uint8_t torus = writer.surface(SurfaceKind::Torus, SolidSide::Below, flat_radius, corner, corner);
      const std::uint8_t torus_region = writer.region(torus, ToolFace::Corner);
      const std::uint8_t corner_top = writer.surface(SurfaceKind::PlaneZ, SolidSide::Below, 0.0, corner, 0.0);
      const std::uint8_t flat_edge = writer.surface(SurfaceKind::Cylinder, SolidSide::Below, 0.0, 0.0, flat_radius);
      return partition(
          writer, corner_top,
          [&] {
            return partition(
                writer, flat_edge,
                [&] { return inside_boundary(writer, bottom, [&] { return region_link(bottom_region); }); },
                [&] { return inside_boundary(writer, torus, [&] { return region_link(torus_region); }); });
          },
          [&] {
            return inside_boundary(writer, side_surface,
                                   [&] { return nearer_of_two(writer, bottom_region, side_region); });
          });
    }
  }
  return kOutside;
}

// The part above z = L: the holder's side and top, and where it is wider than the cutter, the
// downward step around the cutter and the concave edge where the two meet.
BspLink build_holder(TreeWriter& writer, const ToolSpec& spec, std::uint8_t flute_side_surface,
                     std::uint8_t flute_side_region) {
  const double radius = spec.diameter_mm / 2.0;
  const double holder_radius = spec.holder_diameter_mm / 2.0;
  const double total_length = spec.flute_length_mm + spec.holder_length_mm;
  const std::uint8_t top = writer.surface(SurfaceKind::PlaneZ, SolidSide::Below, 0.0, total_length, 0.0);
  const std::uint8_t top_region = writer.region(top, ToolFace::HolderTop);
  if (holder_radius == radius) {
    // One cylinder from the flutes up: the holder's side is the flutes' side.
    return inside_boundary(writer, top, [&] {
      return inside_boundary(writer, flute_side_surface,
                             [&] { return nearer_of_two(writer, flute_side_region, top_region); });
    });
  }
  const std::uint8_t side = writer.surface(SurfaceKind::Cylinder, SolidSide::Below, 0.0, 0.0, holder_radius);
  const std::uint8_t side_region = writer.region(side, ToolFace::HolderSide);
  const std::uint8_t step =
      writer.surface(SurfaceKind::PlaneZ, SolidSide::Above, 0.0, spec.flute_length_mm, 0.0);
  const std::uint8_t step_region = writer.region(step, ToolFace::HolderStep);
  const std::uint8_t edge =
      writer.surface(SurfaceKind::Torus, SolidSide::Above, radius, spec.flute_length_mm, 0.0);
  const std::uint8_t edge_region = writer.region(edge, ToolFace::HolderEdge);
  return inside_boundary(writer, top, [&] {
    return inside_boundary(writer, side, [&] {
      return partition(
          writer, flute_side_surface, [&] { return nearest_of_three(writer, edge_region, side_region, top_region); },
          [&] { return nearest_of_three(writer, step_region, side_region, top_region); });
    });
  });
}

}  // namespace

ToolBuildResult build_tool_bsp(const ToolSpec& spec, ToolBsp& tool) {
  tool = ToolBsp{};
  const ToolBuildResult verdict = check_spec(spec);
  if (!verdict.ok) {
    return verdict;
  }
  const double radius = spec.diameter_mm / 2.0;
  tool.spec = spec;
  tool.envelope = {radius, spec.flute_length_mm, spec.holder_diameter_mm / 2.0,
                   spec.flute_length_mm + spec.holder_length_mm};

  TreeWriter writer(tool);
  const std::uint8_t flute_top =
      writer.surface(SurfaceKind::PlaneZ, SolidSide::Below, 0.0, spec.flute_length_mm, 0.0);
  const std::uint8_t flute_side = writer.surface(SurfaceKind::Cylinder, SolidSide::Below, 0.0, 0.0, radius);
  const std::uint8_t flute_side_region = writer.region(flute_side, ToolFace::FluteSide);
  // The flutes own z < L; the plane z = L itself belongs to the holder, which is at least as wide.
  static_cast<void>(partition(
      writer, flute_top, [&] { return build_cutter(writer, spec, flute_side, flute_side_region); },
      [&] { return build_holder(writer, spec, flute_side, flute_side_region); }));
  return ok();
}

}  // namespace stencil::geometry
