// Sample part geometry and a plain STL writer.
#include "toolchain/tablegen/sample_parts.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <numbers>
#include <sstream>

#include <Eigen/Geometry>

#include "toolchain/tablegen/input_error.hpp"

namespace stencil::tablegen {
namespace {

// Two facets for a quad a-b-c-d, counter-clockwise seen from outside.
void add_quad(std::vector<Facet>& facets, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
              const Eigen::Vector3d& d) {
  facets.push_back({a, b, c});
  facets.push_back({a, c, d});
}

// An axis-aligned box [low, high].
void add_box(std::vector<Facet>& facets, const Eigen::Vector3d& low, const Eigen::Vector3d& high) {
  const auto corner = [&](int x, int y, int z) {
    return Eigen::Vector3d(x ? high.x() : low.x(), y ? high.y() : low.y(), z ? high.z() : low.z());
  };
  add_quad(facets, corner(0, 0, 0), corner(0, 1, 0), corner(1, 1, 0), corner(1, 0, 0));  // bottom, -z
  add_quad(facets, corner(0, 0, 1), corner(1, 0, 1), corner(1, 1, 1), corner(0, 1, 1));  // top, +z
  add_quad(facets, corner(0, 0, 0), corner(1, 0, 0), corner(1, 0, 1), corner(0, 0, 1));  // -y
  add_quad(facets, corner(0, 1, 0), corner(0, 1, 1), corner(1, 1, 1), corner(1, 1, 0));  // +y
  add_quad(facets, corner(0, 0, 0), corner(0, 0, 1), corner(0, 1, 1), corner(0, 1, 0));  // -x
  add_quad(facets, corner(1, 0, 0), corner(1, 1, 0), corner(1, 1, 1), corner(1, 0, 1));  // +x
}

}  // namespace

std::vector<Facet> hexagonal_prism(double circumradius_mm, double height_mm, double cx_mm, double cy_mm) {
  // Each corner computed once, so neighbouring facets share exactly equal vertices (a closed mesh).
  std::array<Eigen::Vector3d, 6> corners;
  for (std::size_t i = 0; i < 6; ++i) {
    const double angle = std::numbers::pi / 3.0 * static_cast<double>(i);
    corners[i] = {cx_mm + circumradius_mm * std::cos(angle), cy_mm + circumradius_mm * std::sin(angle), 0.0};
  }
  std::vector<Facet> facets;
  const Eigen::Vector3d bottom_centre(cx_mm, cy_mm, 0.0);
  const Eigen::Vector3d top_centre(cx_mm, cy_mm, height_mm);
  const Eigen::Vector3d up(0.0, 0.0, height_mm);
  for (std::size_t i = 0; i < 6; ++i) {
    const Eigen::Vector3d& p0 = corners[i];
    const Eigen::Vector3d& p1 = corners[(i + 1) % 6];
    facets.push_back({bottom_centre, p1, p0});          // bottom, facing down
    facets.push_back({top_centre, p0 + up, p1 + up});   // top, facing up
    add_quad(facets, p0, p1, p1 + up, p0 + up);         // side, facing out
  }
  return facets;
}

std::vector<Facet> slotted_block(double length_mm, double width_mm, double height_mm, double slot_width_mm,
                                 double slot_depth_mm, double x_mm, double y_mm) {
  // A U-shaped cross-section in the (y, z) plane, counter-clockwise, extruded along x: one closed
  // solid with no internal faces.
  const double wall = 0.5 * (width_mm - slot_width_mm);
  const double floor = height_mm - slot_depth_mm;
  const std::array<std::array<double, 2>, 8> outline = {{{0.0, 0.0},
                                                         {width_mm, 0.0},
                                                         {width_mm, height_mm},
                                                         {width_mm - wall, height_mm},
                                                         {width_mm - wall, floor},
                                                         {wall, floor},
                                                         {wall, height_mm},
                                                         {0.0, height_mm}}};
  const auto at = [&](std::size_t corner, double x) {
    return Eigen::Vector3d(x, y_mm + outline[corner][0], outline[corner][1]);
  };
  const double x0 = x_mm;
  const double x1 = x_mm + length_mm;
  std::vector<Facet> facets;
  // The end caps: the U cut into six triangles (right wall, floor slab, left wall).
  const std::array<std::array<std::size_t, 3>, 6> cap = {{{1, 2, 3}, {1, 3, 4}, {0, 1, 4}, {0, 4, 5}, {0, 5, 6}, {0, 6, 7}}};
  for (const auto& triangle : cap) {
    facets.push_back({at(triangle[0], x1), at(triangle[1], x1), at(triangle[2], x1)});  // facing +x
    facets.push_back({at(triangle[0], x0), at(triangle[2], x0), at(triangle[1], x0)});  // facing -x
  }
  for (std::size_t i = 0; i < outline.size(); ++i) {
    const std::size_t next = (i + 1) % outline.size();
    add_quad(facets, at(i, x0), at(next, x0), at(next, x1), at(i, x1));
  }
  return facets;
}

std::vector<Facet> thin_fin(double length_mm, double thickness_mm, double height_mm, double x_mm, double y_mm) {
  std::vector<Facet> facets;
  add_box(facets, {x_mm, y_mm, 0.0}, {x_mm + length_mm, y_mm + thickness_mm, height_mm});
  return facets;
}

std::vector<Facet> tessellated_dome(std::size_t triangles, double x0_mm, double y0_mm, double width_mm,
                                    double depth_mm, double base_mm, double bump_mm) {
  // n x m grid cells, two facets each, with n / m = width / depth.
  const double cells = static_cast<double>(triangles) / 2.0;
  const auto n = static_cast<std::size_t>(std::max(1.0, std::round(std::sqrt(cells * width_mm / depth_mm))));
  const auto m = static_cast<std::size_t>(std::max(1.0, std::round(cells / static_cast<double>(n))));
  const auto height = [&](std::size_t i, std::size_t j) {
    const double u = static_cast<double>(i) / static_cast<double>(n);
    const double v = static_cast<double>(j) / static_cast<double>(m);
    return base_mm + bump_mm * std::sin(std::numbers::pi * u) * std::sin(std::numbers::pi * v) *
                         (1.0 + 0.2 * std::cos(6.0 * std::numbers::pi * u));
  };
  const auto top = [&](std::size_t i, std::size_t j) {
    return Eigen::Vector3d(x0_mm + width_mm * static_cast<double>(i) / static_cast<double>(n),
                           y0_mm + depth_mm * static_cast<double>(j) / static_cast<double>(m), height(i, j));
  };
  const auto floor_of = [](Eigen::Vector3d p) {
    p.z() = 0.0;
    return p;
  };
  std::vector<Facet> facets;
  facets.reserve(2 * n * m + 4 * (n + m) + 2);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < m; ++j) {
      add_quad(facets, top(i, j), top(i + 1, j), top(i + 1, j + 1), top(i, j + 1));
    }
  }
  for (std::size_t i = 0; i < n; ++i) {  // walls along y = y0 (facing -y) and y = y0 + depth (facing +y)
    add_quad(facets, floor_of(top(i, 0)), floor_of(top(i + 1, 0)), top(i + 1, 0), top(i, 0));
    add_quad(facets, floor_of(top(i + 1, m)), floor_of(top(i, m)), top(i, m), top(i + 1, m));
  }
  for (std::size_t j = 0; j < m; ++j) {  // walls along x = x0 (facing -x) and x = x0 + width (facing +x)
    add_quad(facets, floor_of(top(0, j + 1)), floor_of(top(0, j)), top(0, j), top(0, j + 1));
    add_quad(facets, floor_of(top(n, j)), floor_of(top(n, j + 1)), top(n, j + 1), top(n, j));
  }
  // No bottom: it stands on the stock floor, which is never cut (the mesh is open there).
  return facets;
}

std::vector<std::byte> encode_stl(const std::vector<Facet>& facets, bool binary, const std::string& solid_name) {
  std::string bytes;
  const auto append = [&](const void* data, std::size_t size) { bytes.append(static_cast<const char*>(data), size); };
  if (binary) {
    char header[80] = {};
    std::snprintf(header, sizeof(header), "binary STL written by stencil-sample-parts: %s", solid_name.c_str());
    append(header, sizeof(header));
    const auto count = static_cast<std::uint32_t>(facets.size());
    append(&count, sizeof(count));
    for (const Facet& facet : facets) {
      const Eigen::Vector3d normal = (facet[1] - facet[0]).cross(facet[2] - facet[0]).normalized();
      float values[12];
      for (int axis = 0; axis < 3; ++axis) {
        values[axis] = static_cast<float>(normal[axis]);
        for (int vertex = 0; vertex < 3; ++vertex) {
          values[3 + 3 * vertex + axis] = static_cast<float>(facet[static_cast<std::size_t>(vertex)][axis]);
        }
      }
      append(values, sizeof(values));
      const std::uint16_t attributes = 0;
      append(&attributes, sizeof(attributes));
    }
  } else {
    std::ostringstream text;
    text.precision(9);
    text << "solid " << solid_name << "\n";
    for (const Facet& facet : facets) {
      const Eigen::Vector3d normal = (facet[1] - facet[0]).cross(facet[2] - facet[0]).normalized();
      text << "  facet normal " << normal.x() << " " << normal.y() << " " << normal.z() << "\n    outer loop\n";
      for (const Eigen::Vector3d& vertex : facet) {
        text << "      vertex " << vertex.x() << " " << vertex.y() << " " << vertex.z() << "\n";
      }
      text << "    endloop\n  endfacet\n";
    }
    text << "endsolid " << solid_name << "\n";
    bytes = text.str();
  }
  std::vector<std::byte> result(bytes.size());
  std::memcpy(result.data(), bytes.data(), bytes.size());
  return result;
}

void write_stl(const std::string& path, const std::vector<Facet>& facets, bool binary, const std::string& solid_name) {
  const std::vector<std::byte> bytes = encode_stl(facets, binary, solid_name);
  std::ofstream file(path, std::ios::binary);
  if (!file) {
    throw InputError(path + ": cannot write (" + std::strerror(errno) + ")");
  }
  file.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!file.flush()) {
    throw InputError(path + ": cannot write (" + std::strerror(errno) + ")");
  }
}

}  // namespace stencil::tablegen
