// The project's own sample parts, generated from their dimensions (so they are ours and exact).
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace stencil::tablegen {

using Facet = std::array<Eigen::Vector3d, 3>;  // counter-clockwise seen from outside

// A hexagonal prism standing on z = 0, centred at (cx, cy): the classic stencil demo.
std::vector<Facet> hexagonal_prism(double circumradius_mm, double height_mm, double cx_mm, double cy_mm);

// A block with a slot through it along x, narrower than a 3 mm tool: the slot is unreachable.
std::vector<Facet> slotted_block(double length_mm, double width_mm, double height_mm, double slot_width_mm,
                                 double slot_depth_mm, double x_mm, double y_mm);

// A thin upright fin (a plate) standing on z = 0.
std::vector<Facet> thin_fin(double length_mm, double thickness_mm, double height_mm, double x_mm, double y_mm);

// A smooth dome-like height field over a rectangle, with about `triangles` facets: the
// benchmark's finely tessellated surface (top and four walls; open at the bottom, on the floor).
std::vector<Facet> tessellated_dome(std::size_t triangles, double x0_mm, double y0_mm, double width_mm,
                                    double depth_mm, double base_mm, double bump_mm);

// The bytes of an ASCII (named `solid_name`) or binary STL of the facets.
std::vector<std::byte> encode_stl(const std::vector<Facet>& facets, bool binary, const std::string& solid_name);

// Writes facets as ASCII (named `solid_name`) or binary STL; throws InputError naming the path.
void write_stl(const std::string& path, const std::vector<Facet>& facets, bool binary, const std::string& solid_name);

}  // namespace stencil::tablegen
