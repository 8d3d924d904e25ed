// A straight move of the upright tool checked for legality along the way: the sweep both the
// virtual tool (every cycle) and the machine planner (every machine update) rely on.
#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "firmware/core/stencil/contact_query.hpp"
#include "firmware/core/tables/part_tables.hpp"

namespace stencil::engine {

// Legal pose of the 3-axis mill's tool (axis +z) with its tip at tip_mm: inside the workspace box
// [0, workspace] (the stock floor is z = 0) and no point of the cloud deeper than the surface
// tolerance inside the tool. Allocation-free, one query.
[[nodiscard]] Legality check_tip_legal(const tables::PartTables& part, const Eigen::Vector3d& tip_mm);

// Longest sub-step that no point of the cloud can slip between: half the tables' achieved spacing.
[[nodiscard]] double sweep_step_mm(const tables::PartTables& part);

enum class SweepStatus : std::uint8_t {
  Legal,    // every sub-step up to `to` is legal
  Illegal,  // a sub-step is illegal: `reached` is the last legal one (or `from`)
  Limited,  // longer than max_steps sub-steps: `reached` is as far as they go, all legal
  Fault,    // bad input or damaged tables
};

struct SweepResult {
  SweepStatus status;
  Eigen::Vector3d reached_mm;  // the last legal sub-step (from itself when none was)
  Eigen::Vector3d blocked_mm;  // Illegal: the first sub-step that was not legal; else to_mm
  int steps;                   // sub-steps checked
};

// Checks the straight move from `from_mm` (assumed legal) to `to_mm` in sub-steps no longer than
// step_mm, at most max_steps of them; the last of them lands exactly on to_mm. Bounded work:
// max_steps legality queries.
[[nodiscard]] SweepResult check_sweep(const tables::PartTables& part, const Eigen::Vector3d& from_mm,
                                      const Eigen::Vector3d& to_mm, double step_mm, int max_steps);

}  // namespace stencil::engine
