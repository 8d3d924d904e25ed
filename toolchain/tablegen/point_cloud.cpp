// Sampling the part's surface: deterministic, covering, and the same whatever the thread count.
#include "toolchain/tablegen/point_cloud.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <thread>

namespace stencil::tablegen {
namespace {

double covering_radius_of(const PartTriangle& triangle) {
  const Eigen::Vector3d& a = triangle.vertices[0];
  const Eigen::Vector3d& b = triangle.vertices[1];
  const Eigen::Vector3d& c = triangle.vertices[2];
  const double ab = (b - a).norm();
  const double bc = (c - b).norm();
  const double ca = (a - c).norm();
  const double longest = std::max({ab, bc, ca});
  const double sum_of_others_squared = ab * ab + bc * bc + ca * ca - longest * longest;
  if (longest * longest >= sum_of_others_squared) {
    return 0.5 * longest;  // right or obtuse: the midpoint of the longest edge is the farthest point
  }
  return ab * bc * ca / (4.0 * triangle.area_mm2);  // acute: the circumradius
}

std::uint32_t pieces_per_edge(const PartTriangle& triangle, double covering_radius_mm) {
  const double k = std::ceil(covering_radius_of(triangle) / covering_radius_mm);
  return static_cast<std::uint32_t>(std::max(1.0, k));
}

// Grid points of a k-subdivided triangle, less its three corners.
std::uint64_t grid_points(std::uint32_t k) {
  const std::uint64_t n = k;
  return (n + 1) * (n + 2) / 2 - 3;
}

// Uniform double in [0, 1) from 53 random bits: the same on every platform, unlike the standard
// distributions.
double unit_interval(std::mt19937_64& random) { return static_cast<double>(random() >> 11) * 0x1.0p-53; }

template <typename Work>
void parallel_for(std::size_t count, unsigned threads, const Work& work) {
  threads = std::max(1u, std::min<unsigned>(threads, static_cast<unsigned>(std::max<std::size_t>(count, 1))));
  if (threads == 1) {
    work(0, count);
    return;
  }
  std::vector<std::thread> workers;
  for (unsigned t = 0; t < threads; ++t) {
    const std::size_t begin = count * t / threads;
    const std::size_t end = count * (t + 1) / threads;
    workers.emplace_back([&, begin, end] { work(begin, end); });
  }
  for (std::thread& worker : workers) {
    worker.join();
  }
}

// Radius of the rounded edge that meets the surface first: the ball, or the bull-nose corner;
// 0 for a flat end mill's sharp corner.
double rounded_edge_radius(const geometry::ToolSpec& tool) {
  switch (tool.kind) {
    case geometry::CutterKind::Ball:
      return tool.diameter_mm / 2.0;
    case geometry::CutterKind::BullNose:
      return tool.corner_radius_mm;
    case geometry::CutterKind::Flat:
      break;
  }
  return 0.0;
}

}  // namespace

double gouge_bound_mm(const geometry::ToolSpec& tool, double covering_radius_mm) {
  const double h = covering_radius_mm;
  const double r = rounded_edge_radius(tool);
  if (h >= r) {
    return h;  // a sharp corner, or samples sparser than the rounding: the edge acts as a corner
  }
  return r - std::sqrt(r * r - h * h);
}

double covering_radius_for_gouge(const geometry::ToolSpec& tool, double max_gouge_mm) {
  const double r = rounded_edge_radius(tool);
  if (max_gouge_mm >= r) {
    return max_gouge_mm;
  }
  return std::sqrt(max_gouge_mm * (2.0 * r - max_gouge_mm));
}

std::uint64_t count_cloud_points(const PartMesh& mesh, const CloudOptions& options) {
  std::uint64_t count = mesh.vertices.size() + mesh.triangles.size() + options.extra_points;
  for (const PartTriangle& triangle : mesh.triangles) {
    count += grid_points(pieces_per_edge(triangle, options.covering_radius_mm));
  }
  return count;
}

PointCloud build_point_cloud(const PartMesh& mesh, const CloudOptions& options,
                             const std::function<void(double)>& progress) {
  PointCloud cloud;
  const std::size_t triangle_count = mesh.triangles.size();

  // Where each triangle's grid points go, so threads can fill them in place.
  std::vector<std::uint64_t> grid_start(triangle_count + 1, 0);
  std::vector<std::uint32_t> pieces(triangle_count);
  double achieved = 0.0;
  for (std::size_t t = 0; t < triangle_count; ++t) {
    pieces[t] = pieces_per_edge(mesh.triangles[t], options.covering_radius_mm);
    grid_start[t + 1] = grid_start[t] + grid_points(pieces[t]);
    achieved = std::max(achieved, covering_radius_of(mesh.triangles[t]) / pieces[t]);
  }
  cloud.achieved_covering_radius_mm = achieved;
  const std::size_t fixed = mesh.vertices.size() + triangle_count;
  cloud.points.resize(fixed + grid_start[triangle_count] + options.extra_points);

  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    const std::uint32_t triangle = mesh.vertex_first_triangle[v];
    cloud.points[v] = {mesh.vertices[v], mesh.triangles[triangle].normal, triangle};
  }
  cloud.vertex_points = mesh.vertices.size();

  parallel_for(triangle_count, options.threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t t = begin; t < end; ++t) {
      const PartTriangle& triangle = mesh.triangles[t];
      const auto id = static_cast<std::uint32_t>(t);
      const Eigen::Vector3d centroid = (triangle.vertices[0] + triangle.vertices[1] + triangle.vertices[2]) / 3.0;
      cloud.points[mesh.vertices.size() + t] = {centroid, triangle.normal, id};
      const std::uint32_t k = pieces[t];
      std::size_t slot = fixed + grid_start[t];
      for (std::uint32_t i = 0; i <= k; ++i) {
        for (std::uint32_t j = 0; i + j <= k; ++j) {
          const std::uint32_t l = k - i - j;
          if (i == k || j == k || l == k) {
            continue;  // a corner: already a vertex point
          }
          const Eigen::Vector3d position =
              (static_cast<double>(i) * triangle.vertices[0] + static_cast<double>(j) * triangle.vertices[1] +
               static_cast<double>(l) * triangle.vertices[2]) /
              static_cast<double>(k);
          cloud.points[slot++] = {position, triangle.normal, id};
        }
      }
      if (begin == 0 && (t & 0xffff) == 0) {
        progress(static_cast<double>(t) / static_cast<double>(end));
      }
    }
  });

  if (options.extra_points > 0) {
    std::vector<double> cumulative_area(triangle_count);
    double total = 0.0;
    for (std::size_t t = 0; t < triangle_count; ++t) {
      total += mesh.triangles[t].area_mm2;
      cumulative_area[t] = total;
    }
    std::mt19937_64 random(options.seed);
    std::size_t slot = fixed + grid_start[triangle_count];
    for (std::uint64_t n = 0; n < options.extra_points; ++n) {
      const double pick = unit_interval(random) * total;
      const auto found = std::upper_bound(cumulative_area.begin(), cumulative_area.end(), pick);
      const std::size_t t = std::min<std::size_t>(static_cast<std::size_t>(found - cumulative_area.begin()), triangle_count - 1);
      const PartTriangle& triangle = mesh.triangles[t];
      // Uniform in the triangle: fold the unit square onto it.
      double u = unit_interval(random);
      double v = unit_interval(random);
      if (u + v > 1.0) {
        u = 1.0 - u;
        v = 1.0 - v;
      }
      const Eigen::Vector3d position =
          triangle.vertices[0] + u * (triangle.vertices[1] - triangle.vertices[0]) + v * (triangle.vertices[2] - triangle.vertices[0]);
      cloud.points[slot++] = {position, triangle.normal, static_cast<std::uint32_t>(t)};
    }
  }

  if (options.allowance_mm != 0.0) {
    for (CloudPoint& point : cloud.points) {
      point.position_mm += options.allowance_mm * point.normal;
    }
  }
  return cloud;
}

}  // namespace stencil::tablegen
