// Remediation: the virtual tool, the only pose ever sent to the machine, kept legal every cycle.
#pragma once

#include <cstdint>
#include <limits>

#include <Eigen/Core>

#include "firmware/core/stencil/contact_query.hpp"
#include "firmware/core/stencil/standoff.hpp"
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
// stock floor (z = 0), and the tip inside the workspace box. With a standoff (StandoffPart), the
// tool checked is the grown one: the real tool keeps the standoff clear of the part and the floor.
// Every position in and out (desired, tip, pose) is the real tool's tip.
class VirtualTool {
 public:
  // `home_tip_mm` must itself be legal (the machine's homed pose, above the part). `part` (or the
  // standoff's view) must outlive the tool.
  VirtualTool(const tables::PartTables& part, const Eigen::Vector3d& home_tip_mm);
  VirtualTool(const StandoffPart& view, const Eigen::Vector3d& home_tip_mm);

  // One cycle: moves towards `desired_tip_mm` as far as legality allows; where the straight way is
  // blocked right at the tip, it slides round the obstacle by one slipped sub-step. Allocation-free,
  // bounded by 2 x kMaxSlipIterations queries and 2 x kMaxSweepSteps legality checks. The cycle already
  // queries the desired pose for the haptic force: pass that result in, so it is not done twice.
  RemediationResult step(const Eigen::Vector3d& desired_tip_mm, const ContactResult& contact_at_desired,
                         const ContactParameters& parameters);
  RemediationResult step(const Eigen::Vector3d& desired_tip_mm, const ContactParameters& parameters) {
    return step(desired_tip_mm, contact_at(desired_tip_mm, parameters), parameters);
  }
  // The contact the engine sees with the real tool's tip at `tip_mm`: the grown tool's, with a
  // standoff (what step() wants passed in, and what the force is rendered from).
  [[nodiscard]] ContactResult contact_at(const Eigen::Vector3d& tip_mm, const ContactParameters& parameters) const {
    return query_contacts(part_, {to_engine(tip_mm), Eigen::Vector3d::UnitZ()}, parameters);
  }

  // The most the tip may move in one step: per axis, and all axes together (|dx| + |dy| + |dz|), so
  // the mill can follow (motion::limit_tool_move gives the figures). Unlimited until set. The cut
  // move keeps its direction and stays on the checked sweep, so it is legal.
  void limit_speed(double max_axis_move_mm, double max_total_move_mm);

  [[nodiscard]] Eigen::Vector3d tip_mm() const { return to_tip(tip_); }
  [[nodiscard]] ToolPose pose() const { return {tip_mm(), Eigen::Vector3d::UnitZ()}; }
  [[nodiscard]] double standoff_mm() const { return standoff_; }
  // Longest sub-step of a sweep: half the tables' achieved point spacing.
  [[nodiscard]] double sweep_step_mm() const { return sweep_step_; }

 private:
  [[nodiscard]] Eigen::Vector3d clamp_to_box(const Eigen::Vector3d& tip) const;
  [[nodiscard]] Eigen::Vector3d to_engine(const Eigen::Vector3d& tip_mm) const {
    return {tip_mm.x(), tip_mm.y(), tip_mm.z() - standoff_};
  }
  [[nodiscard]] Eigen::Vector3d to_tip(const Eigen::Vector3d& engine_mm) const {
    return {engine_mm.x(), engine_mm.y(), engine_mm.z() + standoff_};
  }
  enum class Slip : std::uint8_t { Legal, NotFound, Fault };
  // Moves `candidate` out along the reaction until it is legal, at most kMaxSlipIterations times
  // (the first query's result may be given); `iterations` counts the slips made.
  [[nodiscard]] Slip slip_out(Eigen::Vector3d& candidate, const ContactResult* contact_at_candidate,
                              const ContactParameters& parameters, int& iterations) const;

  const tables::PartTables& part_;  // the standoff's view when there is one: the grown tool
  double standoff_ = 0.0;
  Eigen::Vector3d tip_;             // the engine's tip: the grown tool's, standoff_ below the real one
  Eigen::Vector3d box_high_;
  double sweep_step_;
  double max_axis_move_ = std::numeric_limits<double>::infinity();
  double max_total_move_ = std::numeric_limits<double>::infinity();
};

}  // namespace stencil::engine
