// Coulomb friction of the virtual tool on the part: a friction cone round the surface's normal.
// Inside it the tool sticks where it is; outside it the tool slides, just far enough that the pull
// along the surface is the coefficient times the push into it.
#pragma once

#include <Eigen/Core>

#include "firmware/core/stencil/contact_query.hpp"

namespace stencil::engine {

struct FrictionGoal {
  Eigen::Vector3d goal_mm;  // world: where the virtual tool is to go this cycle (the engine's step
                            // still decides what of that is legal)
  bool in_contact;          // the hand pushes into a surface the desired pose penetrates (a hand
                            // pulling away, or no penetration: the goal is the hand's point)
  bool sticking;            // inside the cone: no motion along the surface
};

// `tip_mm` the virtual tool's tip now, `desired_mm` the hand's (world), `contact_at_desired` the
// contact there (its force gives the surface's outward normal and the contact's share of the
// push), `coupling_n_per_world_mm` the coupling's stiffness in world millimetres (coupling times
// the device scale), `friction` the coefficient (0: no friction, the goal is the desired tip).
// The push into the surface is the coupling's stretch along the normal plus the contact's force;
// the pull along it, the coupling's stretch along the surface. For a tool resting on the surface
// (the cycle decides: it slid onto it, or friction held it there last cycle); a tool still coming
// down to the surface goes to the hand's point as without friction. Real-time safe: fixed work, no
// allocation; anything not finite gives the desired tip (the engine's own checks then decide).
[[nodiscard]] FrictionGoal friction_goal(const Eigen::Vector3d& tip_mm, const Eigen::Vector3d& desired_mm,
                                         const ContactResult& contact_at_desired, double coupling_n_per_world_mm,
                                         double friction);

}  // namespace stencil::engine
