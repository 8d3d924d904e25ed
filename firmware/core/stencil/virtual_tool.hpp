// Remediation: the virtual tool, the only pose ever sent to the machine, kept legal every cycle.
#pragma once

#include <cstdint>
#include <limits>

#include <Eigen/Core>

#include "firmware/core/stencil/contact_query.hpp"
#include "firmware/core/tables/part_tables.hpp"

namespace stencil::engine {

// Bounds on the work of one cycle, and the slip's step beyond the surface.
inline constexpr int kMaxSlipIterations = 8;
inline constexpr int kMaxSweepSteps = 64;
inline constexpr double kSlipClearance_mm = 0.001;  // a slip ends 1 um clear of the surface, not on it
inline constexpr double kMinSlipCosine = 0.5;       // a slip is at most twice the depth (and the clearance)

enum class RemediationStatus : std::uint8_t {
  Followed,      // the desired pose was legal and reached by a legal sweep
  Slipped,       // the desired pose was illegal; the tool slid to a legal pose near it
  Blocked,       // the straight path is blocked (a thin wall): advanced to the last legal sub-step
  Stuck,         // nothing legal was found, or the path is blocked right here: the tool stayed
  SweepLimited,  // the move was longer than the cycle may check: advanced as far as checked
  Fault,         // bad input or damaged tables: the tool stayed, treat as a fault
};

struct RemediationResult {
  RemediationStatus status;
  Eigen::Vector3d tip_mm;     // the virtual tool's tip after this cycle (axis is +z)
  int slip_iterations;
  int sweep_steps;
  bool speed_limited;         // the tool went only part of the way: as fast as the mill can follow
};

// The virtual tool of a 3-axis mill: the axis is always +z; only the tip moves. Legal means no
// point of the cloud deeper than the surface tolerance inside the tool, the tip not below the
// stock floor (z = 0), and the tip inside the workspace box.
class VirtualTool {
 public:
  // `home_tip_mm` must itself be legal (the machine's homed pose, above the part).
  VirtualTool(const tables::PartTables& part, const Eigen::Vector3d& home_tip_mm);

  // One cycle: moves towards `desired_tip_mm` as far as legality allows; where the straight way is
  // blocked right at the tip, it slides round the obstacle by one slipped sub-step. Allocation-free,
  // bounded by 2 x kMaxSlipIterations queries and 2 x kMaxSweepSteps legality checks. The cycle already
  // queries the desired pose for the haptic force: pass that result in, so it is not done twice.
  RemediationResult step(const Eigen::Vector3d& desired_tip_mm, const ContactResult& contact_at_desired,
                         const ContactParameters& parameters);
  RemediationResult step(const Eigen::Vector3d& desired_tip_mm, const ContactParameters& parameters) {
    return step(desired_tip_mm, query_contacts(part_, {desired_tip_mm, Eigen::Vector3d::UnitZ()}, parameters),
                parameters);
  }

  // The most the tip may move in one step: per axis, and all axes together (|dx| + |dy| + |dz|), so
  // the mill can follow (motion::limit_tool_move gives the figures). Unlimited until set. The cut
  // move keeps its direction and stays on the checked sweep, so it is legal.
  void limit_speed(double max_axis_move_mm, double max_total_move_mm);

  [[nodiscard]] const Eigen::Vector3d& tip_mm() const { return tip_; }
  [[nodiscard]] ToolPose pose() const { return {tip_, Eigen::Vector3d::UnitZ()}; }
  // Longest sub-step of a sweep: half the tables' achieved point spacing.
  [[nodiscard]] double sweep_step_mm() const { return sweep_step_; }

 private:
  [[nodiscard]] Eigen::Vector3d clamp_to_box(const Eigen::Vector3d& tip) const;
  enum class Slip : std::uint8_t { Legal, NotFound, Fault };
  // Moves `candidate` out along the reaction until it is legal, at most kMaxSlipIterations times
  // (the first query's result may be given); `iterations` counts the slips made.
  [[nodiscard]] Slip slip_out(Eigen::Vector3d& candidate, const ContactResult* contact_at_candidate,
                              const ContactParameters& parameters, int& iterations) const;

  const tables::PartTables& part_;
  Eigen::Vector3d tip_;
  Eigen::Vector3d box_high_;
  double sweep_step_;
  double max_axis_move_ = std::numeric_limits<double>::infinity();
  double max_total_move_ = std::numeric_limits<double>::infinity();
};

}  // namespace stencil::engine
