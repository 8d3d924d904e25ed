// Units, placement, degenerate facets, welding and the edge census of the part's mesh.
#include "toolchain/tablegen/part_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <tuple>

#include <Eigen/Geometry>

#include "toolchain/tablegen/input_error.hpp"

namespace stencil::tablegen {
namespace {

// A facet whose area is below this fraction of its longest edge squared is a sliver or a point:
// it has no normal worth the name.
constexpr double kDegenerateAreaRatio = 1e-12;
const double kCos10Degrees = std::cos(10.0 * 3.14159265358979323846 / 180.0);

std::string range_text(double low, double high) {
  std::ostringstream text;
  text << "[" << low << ", " << high << "]";
  return text.str();
}

void weld_vertices(PartMesh& mesh) {
  const std::size_t corners = mesh.triangles.size() * 3;
  std::vector<std::uint32_t> order(corners);
  std::iota(order.begin(), order.end(), 0u);
  const auto corner = [&](std::uint32_t index) -> const Eigen::Vector3d& {
    return mesh.triangles[index / 3].vertices[index % 3];
  };
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    const Eigen::Vector3d& p = corner(a);
    const Eigen::Vector3d& q = corner(b);
    return std::tie(p.x(), p.y(), p.z(), a) < std::tie(q.x(), q.y(), q.z(), b);
  });
  std::uint32_t next_id = 0;
  for (std::size_t i = 0; i < corners; ++i) {
    const std::uint32_t index = order[i];
    if (i == 0 || corner(index) != corner(order[i - 1])) {
      mesh.vertices.push_back(corner(index));
      mesh.vertex_first_triangle.push_back(index / 3);  // sorted by index within equal coordinates
      ++next_id;
    }
    mesh.triangles[index / 3].vertex_ids[index % 3] = next_id - 1;
  }
}

void count_edges(PartMesh& mesh) {
  struct Edge {
    std::uint32_t low;
    std::uint32_t high;
    bool forward;  // runs low -> high in its facet
  };
  std::vector<Edge> edges;
  edges.reserve(mesh.triangles.size() * 3);
  for (const PartTriangle& triangle : mesh.triangles) {
    for (int i = 0; i < 3; ++i) {
      const std::uint32_t from = triangle.vertex_ids[static_cast<std::size_t>(i)];
      const std::uint32_t to = triangle.vertex_ids[static_cast<std::size_t>((i + 1) % 3)];
      edges.push_back({std::min(from, to), std::max(from, to), from < to});
    }
  }
  std::sort(edges.begin(), edges.end(), [](const Edge& a, const Edge& b) {
    return std::tie(a.low, a.high, a.forward) < std::tie(b.low, b.high, b.forward);
  });
  for (std::size_t start = 0; start < edges.size();) {
    std::size_t end = start;
    std::size_t forward = 0;
    while (end < edges.size() && edges[end].low == edges[start].low && edges[end].high == edges[start].high) {
      forward += edges[end].forward ? 1u : 0u;
      ++end;
    }
    const std::size_t uses = end - start;
    if (uses == 1) {
      ++mesh.report.open_edges;
    } else if (uses > 2) {
      ++mesh.report.non_manifold_edges;
    } else if (forward != 1) {
      ++mesh.report.inconsistent_edges;
    }
    start = end;
  }
}

}  // namespace

PartMesh prepare_part(const StlMesh& stl, const PlacementOptions& options, const std::string& file_name) {
  PartMesh mesh;
  mesh.report.source_triangles = stl.triangles.size();
  mesh.report.solid_count = stl.solid_count;
  const double to_world = options.millimetres_per_unit * options.scale;
  mesh.triangles.reserve(stl.triangles.size());
  for (const StlTriangle& facet : stl.triangles) {
    PartTriangle triangle{};
    for (std::size_t i = 0; i < 3; ++i) {
      triangle.vertices[i] = facet.vertices[i] * to_world;
    }
    if (options.flip) {
      std::swap(triangle.vertices[1], triangle.vertices[2]);
    }
    const Eigen::Vector3d cross =
        (triangle.vertices[1] - triangle.vertices[0]).cross(triangle.vertices[2] - triangle.vertices[0]);
    const double longest = std::max({(triangle.vertices[1] - triangle.vertices[0]).squaredNorm(),
                                     (triangle.vertices[2] - triangle.vertices[1]).squaredNorm(),
                                     (triangle.vertices[0] - triangle.vertices[2]).squaredNorm()});
    if (!(cross.norm() > kDegenerateAreaRatio * longest) || longest == 0.0) {
      ++mesh.report.degenerate_dropped;
      continue;
    }
    triangle.normal = cross.normalized();
    triangle.area_mm2 = 0.5 * cross.norm();
    // The file's normal is compared in the file's own orientation.
    const Eigen::Vector3d recomputed = options.flip ? Eigen::Vector3d(-triangle.normal) : triangle.normal;
    if (facet.file_normal.squaredNorm() > 0.0 && facet.file_normal.normalized().dot(recomputed) < kCos10Degrees) {
      ++mesh.report.normal_disagreements;
    }
    mesh.triangles.push_back(triangle);
  }
  if (mesh.triangles.empty()) {
    throw InputError(file_name + ": all " + std::to_string(stl.triangles.size()) +
                     " facets are degenerate (zero area); expected at least one real triangle");
  }

  Eigen::Vector3d low = mesh.triangles.front().vertices[0];
  Eigen::Vector3d high = low;
  for (const PartTriangle& triangle : mesh.triangles) {
    for (const Eigen::Vector3d& vertex : triangle.vertices) {
      low = low.cwiseMin(vertex);
      high = high.cwiseMax(vertex);
    }
  }
  if (options.placement == Placement::Center) {
    const Eigen::Vector3d shift(0.5 * options.workspace_mm.x() - 0.5 * (low.x() + high.x()),
                                0.5 * options.workspace_mm.y() - 0.5 * (low.y() + high.y()), -low.z());
    for (PartTriangle& triangle : mesh.triangles) {
      for (Eigen::Vector3d& vertex : triangle.vertices) {
        vertex += shift;
      }
    }
    low += shift;
    high += shift;
  }
  const char* axis_names[] = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    // (Written so that a workspace never given, not a number, refuses every part.)
    if (low[axis] < -1e-9 || !(high[axis] <= options.workspace_mm[axis] + 1e-9)) {
      throw InputError(file_name + ": the placed part spans " + axis_names[axis] + " " +
                       range_text(low[axis], high[axis]) + " mm, outside the workspace " +
                       range_text(0.0, options.workspace_mm[axis]) +
                       " mm; use --place center, --scale or --units, or a larger --workspace");
    }
  }
  mesh.min_mm = low;
  mesh.max_mm = high;

  weld_vertices(mesh);
  count_edges(mesh);
  const Eigen::Vector3d centre = 0.5 * (low + high);
  double six_volume = 0.0;
  for (const PartTriangle& triangle : mesh.triangles) {
    six_volume += (triangle.vertices[0] - centre).dot((triangle.vertices[1] - centre).cross(triangle.vertices[2] - centre));
  }
  mesh.report.signed_volume_mm3 = six_volume / 6.0;
  return mesh;
}

}  // namespace stencil::tablegen
