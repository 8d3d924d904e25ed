// The virtual tool: follow when the sweep is legal, slip along the reaction otherwise, stay when stuck.
#include "firmware/stencil/virtual_tool.hpp"

#include <algorithm>
#include <cmath>

namespace stencil::engine {

VirtualTool::VirtualTool(const tables::PartTables& part, const Eigen::Vector3d& home_tip_mm)
    : part_(part),
      tip_(home_tip_mm),
      box_high_(part.header.workspace_mm[0], part.header.workspace_mm[1], part.header.workspace_mm[2]),
      sweep_step_(0.5 * part.header.covering_radius_mm) {}

bool VirtualTool::inside_box(const Eigen::Vector3d& tip) const {
  return (tip.array() >= 0.0).all() && (tip.array() <= box_high_.array()).all();
}

Eigen::Vector3d VirtualTool::clamp_to_box(const Eigen::Vector3d& tip) const {
  return tip.cwiseMax(Eigen::Vector3d::Zero()).cwiseMin(box_high_);
}

Legality VirtualTool::legal(const Eigen::Vector3d& tip) const {
  if (!inside_box(tip)) {
    return Legality::Illegal;
  }
  return check_legal(part_, {tip, Eigen::Vector3d::UnitZ()});
}

// Checks the straight move from the current tip in sub-steps no longer than sweep_step_, so no
// point of the cloud can slip between two checked poses. Stops at the last legal sub-step.
VirtualTool::Sweep VirtualTool::sweep(const Eigen::Vector3d& to, Eigen::Vector3d& reached, int& steps) const {
  reached = tip_;
  steps = 0;
  const Eigen::Vector3d move = to - tip_;
  const double length = move.norm();
  if (length == 0.0) {
    return Sweep::Legal;
  }
  const double needed = std::ceil(length / sweep_step_);
  const int count = needed > kMaxSweepSteps ? kMaxSweepSteps : static_cast<int>(needed);
  for (int i = 1; i <= count; ++i) {
    // The last of `needed` steps lands exactly on `to`; a limited sweep stops at count full steps.
    const Eigen::Vector3d at = (needed <= kMaxSweepSteps && i == count)
                                   ? to
                                   : Eigen::Vector3d(tip_ + (static_cast<double>(i) * sweep_step_ / length) * move);
    ++steps;
    switch (legal(at)) {
      case Legality::Legal:
        reached = at;
        break;
      case Legality::Illegal:
        return Sweep::Illegal;
      case Legality::Fault:
        return Sweep::Fault;
    }
  }
  return needed > kMaxSweepSteps ? Sweep::Limited : Sweep::Legal;
}

RemediationResult VirtualTool::step(const Eigen::Vector3d& desired_tip_mm, const ContactResult& contact_at_desired,
                                    const ContactParameters& parameters) {
  RemediationResult result{RemediationStatus::Stuck, tip_, 0, 0};
  if (!desired_tip_mm.allFinite()) {
    result.status = RemediationStatus::Fault;
    return result;
  }
  // The floor and the workspace walls are planes of the stencil: project onto them analytically.
  Eigen::Vector3d candidate = clamp_to_box(desired_tip_mm);
  const bool clamped = candidate != desired_tip_mm;
  bool found = false;
  for (int iteration = 0; iteration <= kMaxSlipIterations; ++iteration) {
    // The first candidate is the desired pose itself unless a wall of the box moved it.
    const ContactResult contact = (iteration == 0 && !clamped)
                                      ? contact_at_desired
                                      : query_contacts(part_, {candidate, Eigen::Vector3d::UnitZ()}, parameters);
    if (contact.status != QueryStatus::Ok) {
      result.status = RemediationStatus::Fault;
      return result;
    }
    if (contact.penetrating_points == 0) {
      found = true;
      break;
    }
    if (iteration == kMaxSlipIterations) {
      break;
    }
    // Slip: out along the reaction by the penetration depth and a little more, back into the box.
    const double force = contact.force_n.norm();
    if (!(force > 0.0)) {
      break;  // no direction to slip in
    }
    candidate = clamp_to_box(candidate + (contact.max_depth_mm + kSlipClearance_mm) / force * contact.force_n);
    result.slip_iterations = iteration + 1;
  }
  if (!found) {
    result.status = RemediationStatus::Stuck;
    return result;
  }
  Eigen::Vector3d reached;
  int steps = 0;
  const Sweep sweep_result = sweep(candidate, reached, steps);
  result.sweep_steps = steps;
  switch (sweep_result) {
    case Sweep::Fault:
      result.status = RemediationStatus::Fault;
      return result;
    case Sweep::Illegal:
      // The straight path is blocked (a thin wall between here and there): go up to it, never through.
      result.status = reached == tip_ ? RemediationStatus::Stuck : RemediationStatus::Blocked;
      tip_ = reached;
      break;
    case Sweep::Limited:
      tip_ = reached;
      result.status = RemediationStatus::SweepLimited;
      break;
    case Sweep::Legal:
      tip_ = reached;
      result.status = (result.slip_iterations > 0 || clamped) ? RemediationStatus::Slipped : RemediationStatus::Followed;
      break;
  }
  result.tip_mm = tip_;
  return result;
}

}  // namespace stencil::engine
