// Reachability by an upright tool, with a box test that exploits the tool widening upwards.
#include "toolchain/tablegen/reachability.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <iterator>
#include <thread>

#include "firmware/core/geometry/kdop14.hpp"
#include "firmware/core/geometry/upright_tool.hpp"

namespace stencil::tablegen {
namespace {

// The 14-DOP of a ball end mill's sphere at this tip (empty for other cutters): its diagonal slabs
// hug sloping surfaces better than the box test alone.
geometry::Kdop14 ball_dop(const geometry::ToolSpec& tool, const Eigen::Vector3d& tip) {
  geometry::Kdop14 dop = geometry::Kdop14::empty();
  if (tool.kind == geometry::CutterKind::Ball) {
    const double radius = tool.diameter_mm / 2.0;
    dop.add(tip + Eigen::Vector3d(0.0, 0.0, radius));
    dop = dop.enlarged(radius);
  }
  return dop;
}

bool node_may_touch(const geometry::ToolBsp& tool, const tables::BvhNode& node, const Eigen::Vector3d& tip,
                    const geometry::Kdop14& ball) {
  if (tool.spec.kind == geometry::CutterKind::Ball && node.dop_max[2] - tip.z() < tool.envelope.cutter_radius_mm) {
    geometry::Kdop14 volume;
    std::copy(std::begin(node.dop_min), std::end(node.dop_min), volume.min.begin());
    std::copy(std::begin(node.dop_max), std::end(node.dop_max), volume.max.begin());
    if (!geometry::overlaps(volume, ball)) {
      return false;
    }
  }
  return geometry::upright_box_may_touch(tool, tip, {node.dop_min[0], node.dop_min[1], node.dop_min[2]},
                                         {node.dop_max[0], node.dop_max[1], node.dop_max[2]}, kReachTolerance_mm);
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
  const geometry::Kdop14 ball = ball_dop(input.tool.spec, tip);
  std::array<std::uint32_t, tables::kMaxTreeDepth + 1> stack{};
  std::size_t size = 0;
  stack[size++] = 0;
  while (size > 0) {
    const tables::BvhNode& node = input.nodes[stack[--size]];
    if (!node_may_touch(input.tool, node, tip, ball)) {
      continue;
    }
    if (node.point_count > 0) {
      for (std::uint32_t i = node.first_point; i < node.first_point + node.point_count; ++i) {
        const tables::PackedPoint& p = input.points[i];
        const Eigen::Vector3d local = Eigen::Vector3d(p.x_mm, p.y_mm, p.z_mm) - tip;
        if (!geometry::upright_point_may_be_inside(input.tool, local, kReachTolerance_mm)) {
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
