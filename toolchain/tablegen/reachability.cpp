// Reachability by an upright tool, with a box test that exploits the tool widening upwards.
#include "toolchain/tablegen/reachability.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <iterator>
#include <thread>

#include "firmware/geometry/kdop14.hpp"

namespace stencil::tablegen {
namespace {

// Radius of the tool's widest cross-section at or below height z above the tip (the tool widens
// upwards, since the holder is at least as wide as the cutter).
double radius_up_to(const geometry::ToolSpec& tool, double z) {
  const double radius = tool.diameter_mm / 2.0;
  if (z > tool.flute_length_mm) {
    return tool.holder_diameter_mm / 2.0;
  }
  switch (tool.kind) {
    case geometry::CutterKind::Flat:
      return radius;
    case geometry::CutterKind::Ball:
      return z >= radius ? radius : std::sqrt(std::max(0.0, radius * radius - (radius - z) * (radius - z)));
    case geometry::CutterKind::BullNose: {
      const double corner = tool.corner_radius_mm;
      return z >= corner ? radius
                         : (radius - corner) + std::sqrt(std::max(0.0, corner * corner - (corner - z) * (corner - z)));
    }
  }
  return radius;
}

// The 14-DOP of a ball end mill's sphere at this tip (empty for other cutters).
geometry::Kdop14 ball_dop(const geometry::ToolSpec& tool, const Eigen::Vector3d& tip) {
  geometry::Kdop14 dop = geometry::Kdop14::empty();
  if (tool.kind == geometry::CutterKind::Ball) {
    const double radius = tool.diameter_mm / 2.0;
    dop.add(tip + Eigen::Vector3d(0.0, 0.0, radius));
    dop = dop.enlarged(radius);
  }
  return dop;
}

// Whether the node's box can hold a point inside the upright tool at `tip`.
bool box_may_touch(const geometry::ToolSpec& tool, double total_length, const tables::BvhNode& node,
                   const Eigen::Vector3d& tip, const geometry::Kdop14& ball) {
  const double z_low = node.dop_min[2] - tip.z();
  const double z_high = node.dop_max[2] - tip.z();
  if (z_high < kReachTolerance_mm || z_low > total_length) {
    return false;  // entirely below the tip (within tolerance) or above the holder
  }
  const double dx = std::max({node.dop_min[0] - tip.x(), tip.x() - node.dop_max[0], 0.0});
  const double dy = std::max({node.dop_min[1] - tip.y(), tip.y() - node.dop_max[1], 0.0});
  const double reach = radius_up_to(tool, std::min(z_high, total_length));
  if (dx * dx + dy * dy >= reach * reach) {
    return false;
  }
  // A box wholly below a ball's centre can only meet the ball: test the sphere itself.
  const double radius = tool.diameter_mm / 2.0;
  if (tool.kind == geometry::CutterKind::Ball && z_high < radius) {
    // Both the sphere's own 14-DOP (its slabs hug sloping surfaces) and the box-sphere distance.
    geometry::Kdop14 volume;
    std::copy(std::begin(node.dop_min), std::end(node.dop_min), volume.min.begin());
    std::copy(std::begin(node.dop_max), std::end(node.dop_max), volume.max.begin());
    if (!geometry::overlaps(volume, ball)) {
      return false;
    }
    const double dz = radius - z_high;  // the box's top is the nearest height to the centre
    return dx * dx + dy * dy + dz * dz < radius * radius;
  }
  return true;
}

// Whether a point (relative to the tip) may be inside the tool: the exact outline, tested with
// squares only, so that the BSP is asked about the few points that matter.
bool may_be_inside(const geometry::ToolSpec& tool, const geometry::ToolEnvelope& envelope, const Eigen::Vector3d& local) {
  const double z = local.z();
  if (z < kReachTolerance_mm || z > envelope.total_length_mm) {
    return false;
  }
  const double r_squared = local.x() * local.x() + local.y() * local.y();
  if (z > envelope.flute_length_mm) {
    return r_squared < envelope.holder_radius_mm * envelope.holder_radius_mm;
  }
  const double radius = envelope.cutter_radius_mm;
  if (r_squared >= radius * radius) {
    return false;
  }
  if (tool.kind == geometry::CutterKind::Ball && z < radius) {
    return r_squared + (z - radius) * (z - radius) < radius * radius;
  }
  if (tool.kind == geometry::CutterKind::BullNose && z < tool.corner_radius_mm) {
    const double flat = radius - tool.corner_radius_mm;
    if (r_squared <= flat * flat) {
      return true;
    }
    const double r = std::sqrt(r_squared);
    return (r - flat) * (r - flat) + (z - tool.corner_radius_mm) * (z - tool.corner_radius_mm) <
           tool.corner_radius_mm * tool.corner_radius_mm;
  }
  return true;
}

}  // namespace

bool touching_tip(const geometry::ToolSpec& tool, const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
                  Eigen::Vector3d& tip) {
  if (normal.z() < -1e-9) {
    return false;
  }
  // The tool's outward normal at the contact is m = -normal: radial part m_r along `outward`
  // (horizontal, away from the axis), axial part m_z = -normal.z <= 0.
  const Eigen::Vector3d horizontal(-normal.x(), -normal.y(), 0.0);
  const double m_r = horizontal.norm();
  const double m_z = -normal.z();
  const Eigen::Vector3d outward = m_r > 1e-12 ? Eigen::Vector3d(horizontal / m_r) : Eigen::Vector3d::UnitX();
  const double radius = tool.diameter_mm / 2.0;
  double contact_r = 0.0;  // contact point in the tool frame's meridian plane
  double contact_z = 0.0;
  switch (tool.kind) {
    case geometry::CutterKind::Flat:
      contact_r = m_r > 1e-9 ? radius : 0.0;  // the corner edge, or the bottom under the axis
      break;
    case geometry::CutterKind::Ball:
      contact_r = radius * m_r;
      contact_z = radius + radius * m_z;
      break;
    case geometry::CutterKind::BullNose: {
      const double corner = tool.corner_radius_mm;
      if (m_r > 1e-9) {
        contact_r = (radius - corner) + corner * m_r;
        contact_z = corner + corner * m_z;
      }
      break;
    }
  }
  tip = point - contact_r * outward - contact_z * Eigen::Vector3d::UnitZ();
  return true;
}

bool upright_tool_collides(const ReachInput& input, const Eigen::Vector3d& tip) {
  const geometry::ToolSpec& spec = input.tool.spec;
  const double total_length = input.tool.envelope.total_length_mm;
  const geometry::Kdop14 ball = ball_dop(spec, tip);
  std::array<std::uint32_t, tables::kMaxTreeDepth + 1> stack{};
  std::size_t size = 0;
  stack[size++] = 0;
  while (size > 0) {
    const tables::BvhNode& node = input.nodes[stack[--size]];
    if (!box_may_touch(spec, total_length, node, tip, ball)) {
      continue;
    }
    if (node.point_count > 0) {
      for (std::uint32_t i = node.first_point; i < node.first_point + node.point_count; ++i) {
        const tables::PackedPoint& p = input.points[i];
        const Eigen::Vector3d local = Eigen::Vector3d(p.x_mm, p.y_mm, p.z_mm) - tip;
        if (!may_be_inside(spec, input.tool.envelope, local)) {
          continue;
        }
        const geometry::PointClassification result = geometry::classify_in_tool_frame(input.tool, local);
        if (result.contact == geometry::PointContact::Penetrating && result.depth_mm > kReachTolerance_mm) {
          return true;
        }
      }
      continue;
    }
    const std::uint32_t index = static_cast<std::uint32_t>(&node - input.nodes.data());
    stack[size++] = node.right_child;
    stack[size++] = index + 1;
  }
  return false;
}

std::vector<std::uint8_t> mark_reachable(const ReachInput& input, unsigned threads,
                                         const std::function<void(double)>& progress) {
  const std::size_t count = input.points.size();
  std::vector<std::uint8_t> flags(count, 0);
  // Chunks handed out one at a time keep both threads busy however uneven the work is; every
  // point's flag depends on that point alone, so the result does not depend on the order.
  constexpr std::size_t kChunk = 4096;
  std::atomic<std::size_t> next_chunk{0};
  const auto work = [&](bool reports) {
    for (;;) {
      const std::size_t begin = next_chunk.fetch_add(1) * kChunk;
      if (begin >= count) {
        return;
      }
      const std::size_t end = std::min(count, begin + kChunk);
      for (std::size_t i = begin; i < end; ++i) {
        const tables::PackedPoint& p = input.points[i];
        const tables::PackedPoint& n = input.normals[i];
        Eigen::Vector3d tip;
        if (!touching_tip(input.tool.spec, {p.x_mm, p.y_mm, p.z_mm}, {n.x_mm, n.y_mm, n.z_mm}, tip)) {
          continue;
        }
        const bool in_workspace = (tip.array() >= -kReachTolerance_mm).all() &&
                                  (tip.array() <= input.workspace_mm.array() + kReachTolerance_mm).all();
        if (in_workspace && !upright_tool_collides(input, tip)) {
          flags[i] = tables::kPointReachable;
        }
      }
      if (reports) {
        progress(std::min(1.0, static_cast<double>(end) / static_cast<double>(count)));
      }
    }
  };
  std::vector<std::thread> workers;
  for (unsigned t = 1; t < std::max(1u, threads); ++t) {
    workers.emplace_back(work, false);
  }
  work(true);
  for (std::thread& worker : workers) {
    worker.join();
  }
  return flags;
}

}  // namespace stencil::tablegen
