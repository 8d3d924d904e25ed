// The friction cone: stick inside, slide to its edge outside.
#include "firmware/core/stencil/surface_friction.hpp"

#include <cmath>

namespace stencil::engine {

FrictionGoal friction_goal(const Eigen::Vector3d& tip_mm, const Eigen::Vector3d& desired_mm,
                           const ContactResult& contact_at_desired, double coupling_n_per_world_mm, double friction) {
  const FrictionGoal unheld{desired_mm, false, false};
  const double contact_n = contact_at_desired.force_n.norm();
  if (!(friction > 0.0) || !(coupling_n_per_world_mm > 0.0) || !std::isfinite(friction) ||
      !std::isfinite(coupling_n_per_world_mm) || contact_at_desired.status != QueryStatus::Ok ||
      contact_at_desired.penetrating_points == 0 || !(contact_n > 0.0) || !std::isfinite(contact_n) ||
      !tip_mm.allFinite() || !desired_mm.allFinite()) {
    return unheld;
  }
  const Eigen::Vector3d normal = contact_at_desired.force_n / contact_n;  // out of the part, on the tool
  const Eigen::Vector3d stretch = desired_mm - tip_mm;
  const double push_mm = -stretch.dot(normal);  // how far the hand is in past the tool, along the normal
  if (!(push_mm > 0.0)) {
    return unheld;  // pulling away from the surface: nothing holds the tool
  }
  const double push_n = coupling_n_per_world_mm * push_mm + contact_n;
  const Eigen::Vector3d along = stretch + push_mm * normal;  // the stretch's part along the surface
  const double along_mm = along.norm();
  // The pull along the surface the cone allows, as a stretch of the coupling (world mm).
  const double allowed_mm = friction * push_n / coupling_n_per_world_mm;
  // The goal is relative to the tool, not to the hand: the contact's direction at the hand's pose
  // wavers by a percent or two with the points' spacing, and a goal kept along it would creep.
  if (along_mm <= allowed_mm) {
    return {tip_mm, true, true};  // sticking: the tool stays
  }
  // Slipping: the tool slides along until the stretch left along the surface is the cone's edge.
  return {tip_mm + along * (1.0 - allowed_mm / along_mm), true, false};
}

}  // namespace stencil::engine
