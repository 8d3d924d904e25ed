// What the simulated mill did to the part, measured from ground truth only: the path the mill's
// tool really followed (after backlash), cut into the stock's Z-map, and the deepest penetration of
// the true tool into the part's own triangles anywhere along it.
#pragma once

#include <array>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <vector>

#include <Eigen/Core>

#include "firmware/core/motion/machine_frames.hpp"
#include "firmware/core/tables/part_tables.hpp"
#include "sim/mill/simulated_mill.hpp"
#include "sim/mill/stock_zmap.hpp"

namespace stencil::sim {

// The part's top over each cell centre of `grid` (the floor's height where there is no part):
// the highest of the part's triangles above it, row-major.
[[nodiscard]] std::vector<double> part_top_heights(const tables::PartTables& part, const StockZmap& grid);

// Over the cells of `grid`, given the part's top over each (part_heights, row-major): the lowest the
// tool's tip can be over each cell without the tool entering the part or going below the floor.
[[nodiscard]] std::vector<double> lowest_tips(const StockZmap& grid, const std::vector<double>& part_heights,
                                              const ToolProfile& tool);

// The deepest a ball end mill's cutter (ball and flutes; the tables' tool) goes into the part's
// triangles anywhere along the straight move from `from` to `to` (tips, world mm); 0 where it stays
// clear. The gouge of a leg, and what a G-code move would do to the part unguarded.
[[nodiscard]] double tool_depth_along(const tables::PartTables& part, const Eigen::Vector3d& from, const Eigen::Vector3d& to);

// One corner of the path the mill followed: where the moving axis changed or motion stopped.
struct PathCorner {
  double t_s;
  Eigen::Vector3d tip_mm;
};

// Listens to the simulated mill: every move of an axis extends the current straight leg; a leg
// ends when another axis moves or flush() is called (motion stopped). Each finished leg is cut into
// the Z-map and measured against the part's triangles.
class MachinedPart final : public MillMotionObserver {
 public:
  // `now_s` gives the simulated time of a step, for the trace.
  MachinedPart(const tables::PartTables& part, const StockBox& stock, const motion::MachineFrames& frames,
               std::function<double()> now_s);

  // From now on the mill's axis positions `home_axis_steps` are the machine's home (the frames'
  // step 0): recording starts.
  void arm(const std::array<std::int64_t, kMillAxisCount>& home_axis_steps);
  void axis_moved(Axis axis, const std::array<std::int64_t, kMillAxisCount>& axis_steps) override;
  // Motion stopped: the current leg ends here.
  void flush();
  // A leg the mill made before this run (a resumed job's journal), world mm: cut and measured as one
  // it follows would be. Before arm().
  void cut_recorded_leg(const Eigen::Vector3d& from_mm, const Eigen::Vector3d& to_mm);

  // The stock the job means to leave on the part: the controller keeps its virtual tool this far
  // clear of it (its standoff), so what this tool can reach is measured for the tool kept as far
  // off, and the allowance's own volume apart (Volumes::allowance_mm3). 0 until set.
  void set_allowance(double standoff_mm) { allowance_mm_ = standoff_mm; }

  // Every corner is also written to `trace` as t_s,x_mm,y_mm,z_mm (null: none).
  void set_trace(std::FILE* trace) { trace_ = trace; }

  [[nodiscard]] const StockZmap& stock() const { return stock_; }
  // The deepest the ball end mill's cutter (ball and flutes) went into the part's triangles along
  // the whole path, mm; only a ball end mill is measured (measured() says).
  [[nodiscard]] double max_gouge_mm() const { return max_gouge_mm_; }
  [[nodiscard]] bool gouge_measured() const { return gouge_measured_; }
  [[nodiscard]] std::uint64_t legs() const { return legs_; }
  [[nodiscard]] const PathCorner& last_corner() const { return last_corner_; }

  // The part's top surface over each Z-map cell (the floor where there is no part), the lowest the
  // stock can be cut over each cell by this tool without entering the part, and what follows:
  // computed once, at the end of a job.
  struct Volumes {
    double removed_mm3;
    double gouge_mm3;         // stock cut below the part's top surface
    double unmachined_mm3;    // stock this tool could have removed, still there (beyond the allowance)
    double reachable_mm3;     // all the stock this tool could have removed (kept the allowance off)
    double allowance_mm3;     // the stock the allowance leaves on the part
    std::vector<double> unmachined_per_cell_mm;  // over each cell, how thick what is left there is
  };
  [[nodiscard]] Volumes volumes() const;
  [[nodiscard]] std::vector<double> part_heights() const;
  // Over each cell of the stock, the signed distance from its top to the part's triangles, given
  // the part's top over each (part_heights()), exact within `reach_mm` (surface_distance.hpp).
  [[nodiscard]] std::vector<float> signed_distances(const std::vector<double>& part_heights, double reach_mm) const;
  [[nodiscard]] const ToolProfile& tool() const { return tool_; }

 private:
  [[nodiscard]] Eigen::Vector3d world_of(const std::array<std::int64_t, kMillAxisCount>& axis_steps) const;
  void finish_leg();
  [[nodiscard]] double leg_gouge(const Eigen::Vector3d& from, const Eigen::Vector3d& to) const;
  void corner(const Eigen::Vector3d& tip);
  // The lowest the tool's surface can come over each cell from any legal tip (the reachable surface).
  // With an allowance: the tool's tip kept allowance_mm off the part (the tool grown by it).
  [[nodiscard]] std::vector<double> reachable_heights(const std::vector<double>& part, double allowance_mm) const;

  const tables::PartTables& part_;
  motion::MachineFrames frames_;
  std::function<double()> now_s_;
  StockZmap stock_;
  ToolProfile tool_;
  double allowance_mm_ = 0.0;
  std::array<std::int64_t, kMillAxisCount> home_{};
  bool armed_ = false;
  int leg_axis_ = -1;
  Eigen::Vector3d leg_start_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d leg_end_ = Eigen::Vector3d::Zero();
  double max_gouge_mm_ = 0.0;
  bool gouge_measured_ = false;
  std::uint64_t legs_ = 0;
  std::FILE* trace_ = nullptr;
  PathCorner last_corner_{0.0, Eigen::Vector3d::Zero()};
};

}  // namespace stencil::sim
