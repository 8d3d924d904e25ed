// The collision query: which points of the part are inside the tool at a pose, how deep, and the
// force and torque they push back with. Allocation-free, bounded, deterministic: runs in the cycle.
#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "firmware/core/geometry/tool_bsp.hpp"
#include "firmware/core/geometry/tool_spec.hpp"
#include "firmware/core/stencil/tool_pose.hpp"
#include "firmware/core/stencil/triangle_set.hpp"
#include "firmware/core/tables/part_tables.hpp"

namespace stencil::engine {

struct ContactParameters {
  double stiffness_n_per_device_mm = 1.0;  // k, per millimetre of device motion
  double device_mm_per_world_mm = 10.0;    // the rig's haptic-to-machine scale
  double compliance_centre_mm = 10.0;      // distance from the tip up the axis to the compliance centre
};

enum class QueryStatus : std::uint8_t {
  Ok,
  BadInput,     // a pose that is not finite or an axis that is not unit length: no contacts computed
  BadTree,      // the tool tree or the points' tree is damaged: treat as a fault
};

struct ContactResult {
  QueryStatus status;
  std::uint32_t penetrating_points;
  double max_depth_mm;          // world millimetres, 0 when nothing penetrates
  std::uint32_t deepest_point;  // table index of the point at max_depth_mm (valid when penetrating_points > 0)
  Eigen::Vector3d force_n;      // on the tool, magnitude k * 10 * max_depth (world) = k * device penetration
  Eigen::Vector3d torque_nmm;   // about the compliance centre, scaled with the force
};

// Every point within the tool at `pose`. Per penetrating point i, f_i = k_world * d_i along v_i,
// the normalised average of the point's normal and minus the tool's escape direction; the sum is
// rescaled to magnitude k_world * d_max (so stiffness does not grow with point density), and the
// torque sum r_i x f_i about the compliance centre by the same factor. The count, the deepest
// point and its depth are exact (double precision); a leaf of the points' tree lying wholly deeper
// than the tolerance adds its points' forces from its moments where their error estimate allows
// (leaf_moment_force: at 1e6 points in the bench's deep corner the force's direction moves by
// 0.14 degrees and its torque per newton by 0.014 mm against the points' own sum).
[[nodiscard]] ContactResult query_contacts(const tables::PartTables& part, const ToolPose& pose,
                                           const ContactParameters& parameters);

enum class Legality : std::uint8_t { Legal, Illegal, Fault };

// Legal when no point is deeper than the surface tolerance inside the tool (touching is legal).
// Stops at the first penetrating point.
[[nodiscard]] Legality check_legal(const tables::PartTables& part, const ToolPose& pose);

// The tool grown by contact_tolerance_mm all round (its tip lowered by as much), for mark_touched.
// Built once at start-up; false when the grown tool is not a valid tool.
[[nodiscard]] bool build_contact_tool(const geometry::ToolSpec& spec, double contact_tolerance_mm,
                                      geometry::ToolBsp& contact_tool);

// Marks the triangle of every point within about contact_tolerance_mm of the tool's surface (or
// inside it) at `pose`, using the grown tool from build_contact_tool: call it at the virtual tool's
// pose, never the device's. Returns how many triangles were new.
std::uint32_t mark_touched(const tables::PartTables& part, const geometry::ToolBsp& contact_tool, const ToolPose& pose,
                           double contact_tolerance_mm, TriangleSet& touched);

}  // namespace stencil::engine
