// The virtual tool: follow when the sweep is legal, slip along the reaction otherwise, stay when stuck.
#include "firmware/core/stencil/virtual_tool.hpp"

#include <algorithm>
#include <cmath>

#include "firmware/core/stencil/move_limit.hpp"
#include "firmware/core/stencil/sweep.hpp"

namespace stencil::engine {
namespace {

// How far to move along the reaction to clear the deepest point: its depth (and the clearance)
// measured along the reaction, i.e. divided by the cosine between the reaction and the way that
// point leaves the tool. Into a face the two agree (cosine 1: the depth itself); into a concave
// corner the reaction is the bisector and the plain depth would clear each face by only cos 45
// of it, so the slip would creep up on the surface over several re-queries. The cosine is taken no
// lower than kMinSlipCosine, so a slip is never longer than twice the depth; the re-query decides.
double slip_length_mm(const tables::PartTables& part, const Eigen::Vector3d& tip_mm, const ContactResult& contact,
                      const Eigen::Vector3d& reaction) {
  const double length = contact.max_depth_mm + kSlipClearance_mm;
  const tables::PackedPoint& p = part.points[contact.deepest_point];
  const geometry::PointClassification deepest =
      geometry::classify_at_pose(part.tool, tip_mm, Eigen::Vector3d::UnitZ(), {p.x_mm, p.y_mm, p.z_mm});
  // The tool moving along the reaction is the point moving against it: its depth falls at the rate
  // -escape . reaction.
  const double cosine = -deepest.escape_direction.dot(reaction);
  if (deepest.contact != geometry::PointContact::Penetrating || !(cosine > kMinSlipCosine)) {
    return length / kMinSlipCosine;
  }
  return length / cosine;
}

}  // namespace

VirtualTool::VirtualTool(const StandoffPart& view, const Eigen::Vector3d& home_tip_mm)
    : part_(view.part),
      standoff_(view.standoff_mm),
      tip_(view.to_engine(home_tip_mm)),
      box_high_(view.part.header.workspace_mm[0], view.part.header.workspace_mm[1], view.part.header.workspace_mm[2]),
      sweep_step_(engine::sweep_step_mm(view.part)) {}

VirtualTool::VirtualTool(const tables::PartTables& part, const Eigen::Vector3d& home_tip_mm)
    : part_(part),
      tip_(home_tip_mm),
      box_high_(part.header.workspace_mm[0], part.header.workspace_mm[1], part.header.workspace_mm[2]),
      sweep_step_(engine::sweep_step_mm(part)) {}

void VirtualTool::limit_speed(double max_axis_move_mm, double max_total_move_mm) {
  max_axis_move_ = max_axis_move_mm;
  max_total_move_ = max_total_move_mm;
}

Eigen::Vector3d VirtualTool::clamp_to_box(const Eigen::Vector3d& tip) const {
  return tip.cwiseMax(Eigen::Vector3d::Zero()).cwiseMin(box_high_);
}

VirtualTool::Slip VirtualTool::slip_out(Eigen::Vector3d& candidate, const ContactResult* contact_at_candidate,
                                        const ContactParameters& parameters, int& iterations) const {
  for (int iteration = 0; iteration <= kMaxSlipIterations; ++iteration) {
    const ContactResult contact = (iteration == 0 && contact_at_candidate != nullptr)
                                      ? *contact_at_candidate
                                      : query_contacts(part_, {candidate, Eigen::Vector3d::UnitZ()}, parameters);
    if (contact.status != QueryStatus::Ok) {
      return Slip::Fault;
    }
    if (contact.penetrating_points == 0) {
      return Slip::Legal;
    }
    if (iteration == kMaxSlipIterations) {
      break;
    }
    // Slip: out along the reaction by the penetration depth and a little more, back into the box.
    const double force = contact.force_n.norm();
    if (!(force > 0.0)) {
      break;  // no direction to slip in
    }
    const Eigen::Vector3d reaction = contact.force_n / force;
    const double slip = slip_length_mm(part_, candidate, contact, reaction);
    candidate = clamp_to_box(candidate + slip * reaction);
    iterations = iteration + 1;
  }
  return Slip::NotFound;
}

RemediationResult VirtualTool::step(const Eigen::Vector3d& desired_tip_mm, const ContactResult& contact_at_desired,
                                    const ContactParameters& parameters) {
  RemediationResult result{RemediationStatus::Stuck, tip_mm(), 0, 0, false};
  if (!desired_tip_mm.allFinite()) {
    result.status = RemediationStatus::Fault;
    return result;
  }
  // The floor and the workspace walls are planes of the stencil: project onto them analytically.
  const Eigen::Vector3d desired = to_engine(desired_tip_mm);
  Eigen::Vector3d candidate = clamp_to_box(desired);
  const bool clamped = candidate != desired;
  // The first candidate is the desired pose itself unless a wall of the box moved it.
  switch (slip_out(candidate, clamped ? nullptr : &contact_at_desired, parameters, result.slip_iterations)) {
    case Slip::Fault:
      result.status = RemediationStatus::Fault;
      return result;
    case Slip::NotFound:
      result.status = RemediationStatus::Stuck;
      return result;
    case Slip::Legal:
      break;
  }
  SweepResult sweep = check_sweep(part_, tip_, candidate, sweep_step_, kMaxSweepSteps);
  bool slid = false;
  if (sweep.status == SweepStatus::Illegal && sweep.reached_mm == tip_) {
    // Blocked right here: the straight way to a legal pose cuts a corner of the part. Slide along
    // the part instead: the first blocked sub-step slipped out of it, if the short sweep there is
    // legal. Each cycle gains a sub-step round the obstacle; none goes through it.
    Eigen::Vector3d around = sweep.blocked_mm;
    int around_slips = 0;
    const Slip slip = slip_out(around, nullptr, parameters, around_slips);
    if (slip == Slip::Fault) {
      result.status = RemediationStatus::Fault;
      return result;
    }
    if (slip == Slip::Legal) {
      const SweepResult short_sweep = check_sweep(part_, tip_, around, sweep_step_, kMaxSweepSteps);
      if (short_sweep.status == SweepStatus::Legal || short_sweep.status == SweepStatus::Limited) {
        sweep = short_sweep;
        result.slip_iterations += around_slips;
        slid = true;
      }
    }
  }
  // Every point between the tip and `reached` was checked, so a shorter move along it is legal too.
  const Eigen::Vector3d reached =
      shorten_move(tip_, sweep.reached_mm, max_axis_move_, max_total_move_, result.speed_limited);
  result.sweep_steps = sweep.steps;
  switch (sweep.status) {
    case SweepStatus::Fault:
      result.status = RemediationStatus::Fault;
      return result;
    case SweepStatus::Illegal:
      // The straight path is blocked (a thin wall between here and there): go up to it, never through.
      result.status = reached == tip_ ? RemediationStatus::Stuck : RemediationStatus::Blocked;
      tip_ = reached;
      break;
    case SweepStatus::Limited:
      tip_ = reached;
      result.status = slid ? RemediationStatus::Slipped : RemediationStatus::SweepLimited;
      break;
    case SweepStatus::Legal:
      tip_ = reached;
      result.status =
          (result.slip_iterations > 0 || clamped || slid) ? RemediationStatus::Slipped : RemediationStatus::Followed;
      break;
  }
  result.tip_mm = tip_mm();
  return result;
}

}  // namespace stencil::engine
