// The path the mill was commanded, as G-code moves: the journal's machine targets turned back into
// the legs the mill made (the CY545's one-axis staircase in the recorded order, or LinuxCNC's one
// straight segment), each with the time it took, and long runs of tiny collinear moves merged.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "firmware/core/control/machine_record.hpp"
#include "firmware/core/motion/machine_planner.hpp"
#include "firmware/core/tables/part_tables.hpp"

namespace stencil::gcode {

enum class MoveKind : std::uint8_t {
  Traverse,  // G0: the way to and from the cut (home, the retract), not a commanded target
  Feed,      // G1: a leg of the commanded path
};

struct CutMove {
  MoveKind kind;
  Eigen::Vector3d to_mm;  // world = work coordinates
  double seconds;         // how long the mill took (Feed); 0 for a traverse
};

struct CutPathSettings {
  motion::MachinePath path = motion::MachinePath::Staircase;
  Eigen::Vector3d home_world_mm = Eigen::Vector3d::Zero();  // where the tool stands after homing
  double update_s = 1.0 / 30.0;  // one machine update: the time a target's legs take at most
};

// Builds the moves from the journal's events, in order. Each homing starts at the machine's home:
// the way there is a retract to home's height (the top of the travel, above anything), across, and
// down. The staircase's legs of one target share the update's time in proportion to their length.
class CutPath {
 public:
  explicit CutPath(const CutPathSettings& settings) : settings_(settings) {}

  void homed();
  // False (with `error`) for a target before any homing, or one that is not finite.
  [[nodiscard]] bool command(const control::MachineCommandRecord& record, std::string& error);

  [[nodiscard]] const std::vector<CutMove>& moves() const { return moves_; }
  [[nodiscard]] std::uint64_t targets() const { return targets_; }

 private:
  void feed_to(const Eigen::Vector3d& to, double seconds);

  CutPathSettings settings_;
  std::vector<CutMove> moves_;
  Eigen::Vector3d at_ = Eigen::Vector3d::Zero();
  bool homed_ = false;
  std::uint64_t targets_ = 0;
};

struct MergeResult {
  std::vector<CutMove> moves;
  std::uint64_t merged_away = 0;   // moves absorbed into a longer one
  std::uint64_t sweep_checks = 0;  // merged segments checked legal with the engine's sweep
};

// Consecutive feed moves merged into one where every corner dropped lies within `tolerance_mm` of
// the merged segment and their speeds agree within 10 %. A merge that leaves the recorded path (any
// corner off the segment by more than 1e-9 mm) is made only if the engine's sweep check finds the
// merged segment legal: the tolerance is inside the legality check, never on top of it. The merged
// move takes the time of the moves it replaces.
[[nodiscard]] MergeResult merge_collinear(const std::vector<CutMove>& moves, const Eigen::Vector3d& start_mm,
                                          const tables::PartTables& part, double tolerance_mm);

}  // namespace stencil::gcode
