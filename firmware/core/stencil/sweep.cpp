// The checked straight move of the upright tool.
#include "firmware/core/stencil/sweep.hpp"

#include <cmath>

namespace stencil::engine {

Legality check_tip_legal(const tables::PartTables& part, const Eigen::Vector3d& tip_mm) {
  if (!tip_mm.allFinite()) {
    return Legality::Fault;
  }
  const Eigen::Vector3d high(part.header.workspace_mm[0], part.header.workspace_mm[1], part.header.workspace_mm[2]);
  if (!((tip_mm.array() >= 0.0).all() && (tip_mm.array() <= high.array()).all())) {
    return Legality::Illegal;
  }
  return check_legal(part, {tip_mm, Eigen::Vector3d::UnitZ()});
}

double sweep_step_mm(const tables::PartTables& part) { return 0.5 * part.header.covering_radius_mm; }

SweepResult check_sweep(const tables::PartTables& part, const Eigen::Vector3d& from_mm, const Eigen::Vector3d& to_mm,
                        double step_mm, int max_steps) {
  SweepResult result{SweepStatus::Legal, from_mm, to_mm, 0};
  if (!from_mm.allFinite() || !to_mm.allFinite() || !(step_mm > 0.0) || max_steps < 1) {
    result.status = SweepStatus::Fault;
    return result;
  }
  const Eigen::Vector3d move = to_mm - from_mm;
  const double length = move.norm();
  if (length == 0.0) {
    return result;
  }
  const double needed = std::ceil(length / step_mm);
  const int count = needed > max_steps ? max_steps : static_cast<int>(needed);
  for (int i = 1; i <= count; ++i) {
    // The last of `needed` steps lands exactly on `to`; a limited sweep stops at count full steps.
    const Eigen::Vector3d at = (needed <= max_steps && i == count)
                                   ? to_mm
                                   : Eigen::Vector3d(from_mm + (static_cast<double>(i) * step_mm / length) * move);
    ++result.steps;
    switch (check_tip_legal(part, at)) {
      case Legality::Legal:
        result.reached_mm = at;
        break;
      case Legality::Illegal:
        result.status = SweepStatus::Illegal;
        result.blocked_mm = at;
        return result;
      case Legality::Fault:
        result.status = SweepStatus::Fault;
        return result;
    }
  }
  result.status = needed > max_steps ? SweepStatus::Limited : SweepStatus::Legal;
  return result;
}

}  // namespace stencil::engine
